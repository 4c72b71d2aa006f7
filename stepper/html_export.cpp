// The HTML export; see html_export.h.
#include "stepper/html_export.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scene/write_image.h"
#include "stepper/explain.h"
#include "stepper/stages.h"

namespace prast::stepper {

std::string html_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        default: out += c;
        }
    }
    return out;
}

std::string export_html(FrameSetup& s, const Recording& rec, const std::string& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) return dir + ": cannot create the directory" + (ec ? " (" + ec.message() + ")" : "");
    std::vector<std::string> names;
    for (const StageInfo& st : stage_list()) names.push_back(st.name);
    std::vector<std::vector<std::uint8_t>> images;
    draw_stages(s, rec, names, images);
    for (std::size_t i = 0; i < names.size(); ++i) {
        try {
            write_png_atomic((fs::path(dir) / (names[i] + ".png")).string(), rec.width, rec.height, images[i].data());
        } catch (const std::exception& e) {
            return e.what();
        }
    }

    std::ostringstream h;
    h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<title>prast step: the stages of a frame</title>\n<style>\n"
      << "body { font-family: sans-serif; margin: 2em auto; max-width: 1400px; background: #16181d; color: #ddd; }\n"
      << "h1 { font-weight: normal; } a { color: #8cf; }\n"
      << "pre { background: #0d0e11; padding: 1em; overflow-x: auto; font-size: 12px; }\n"
      << ".stages { display: grid; grid-template-columns: repeat(auto-fill, minmax(420px, 1fr)); gap: 1.5em; }\n"
      << "figure { margin: 0; } figure img { width: 100%; image-rendering: pixelated; border: 1px solid #333; }\n"
      << "figcaption b { display: block; margin: 0.4em 0 0.2em; color: #fff; }\n"
      << "</style>\n</head>\n<body>\n"
      << "<h1>From triangles to pixels: the stages of one frame</h1>\n"
      << "<p>Made by <code>step --out</code> (prast). Each image is one stage of the pipeline or one channel of the "
      << "shading, drawn from a recording of the frame; the last one is the image <code>render</code> writes. "
      << "Run <code>step</code> with the same flags and type <code>pixel X Y</code> for any pixel's history.</p>\n"
      << "<pre>" << html_escape(frame_text(s, rec)) << "</pre>\n<div class=\"stages\">\n";
    for (const StageInfo& st : stage_list()) {
        h << "<figure id=\"" << st.name << "\"><a href=\"" << st.name << ".png\"><img src=\"" << st.name
          << ".png\" alt=\"" << html_escape(st.title) << "\" width=\"" << rec.width << "\" height=\"" << rec.height
          << "\"></a>\n<figcaption><b>" << html_escape(st.title) << " <code>(" << st.name << ")</code></b>"
          << html_escape(st.about) << "</figcaption></figure>\n";
    }
    h << "</div>\n</body>\n</html>\n";
    const fs::path index = fs::path(dir) / "index.html";
    const fs::path tmp = fs::path(dir) / ".index.html.tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        out << h.str();
        if (!out) return index.string() + ": cannot write";
    }
    fs::rename(tmp, index, ec);
    if (ec) return index.string() + ": cannot write (" + ec.message() + ")";
    return "";
}

} // namespace prast::stepper
