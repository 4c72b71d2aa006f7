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

namespace {

std::string percent(double t) {
    std::ostringstream o;
    o << t * 100.0 << "%";
    return o.str();
}

// A stage's legend as HTML: a colour bar with ticks (ramp), one bar per
// channel, or swatches (classes and the colours off the scale).
std::string legend_html(const StageScale& sc) {
    if (sc.kind == "picture") return "";
    std::ostringstream h;
    h << "<div class=\"legend\"><div class=\"quantity\">" << html_escape(sc.quantity)
      << (sc.units.empty() ? "" : " (" + html_escape(sc.units) + ")") << "</div>\n";
    if (sc.kind == "ramp") {
        h << "<div class=\"bar\" style=\"background: linear-gradient(to right";
        for (const auto& [t, c] : sc.stops) h << ", " << css_colour(c.rgb) << " " << percent(t);
        h << ")\"></div><div class=\"ticks\">";
        for (const auto& [t, label] : sc.ticks)
            h << "<span style=\"left: " << percent(t) << "\"" << (t > 0.95 ? " class=\"end\"" : "") << ">"
              << html_escape(label) << "</span>";
        h << "</div>\n";
    } else if (sc.kind == "channels") {
        static const char* kChannel[] = {"#ff0000", "#00ff00", "#0000ff"};
        for (std::size_t k = 0; k < sc.channels.size() && k < 3; ++k)
            h << "<div class=\"channel\"><span class=\"name\">" << html_escape(sc.channels[k])
              << "</span><span class=\"bar\" style=\"background: linear-gradient(to right, #000000, " << kChannel[k]
              << ")\"></span><span>" << sc.min << " .. " << sc.max << "</span></div>\n";
        h << "<div class=\"note\">"
          << (sc.srgb ? "sRGB-encoded" : "linear: the byte is (value - min) / (max - min) * 255") << "</div>\n";
    }
    if (!sc.classes.empty()) {
        h << "<div class=\"classes\">";
        for (const LegendColour& c : sc.classes)
            h << "<span><i style=\"background: " << css_colour(c.rgb) << "\"></i>" << html_escape(c.label) << "</span>";
        h << "</div>\n";
    }
    h << "</div>\n";
    return h.str();
}

} // namespace

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
      << "body { font-family: sans-serif; margin: 2em auto; padding: 0 1em; max-width: 2400px; background: #16181d; "
      << "color: #ddd; }\n"
      << "h1 { font-weight: normal; } a { color: #8cf; }\n"
      << "pre { background: #0d0e11; padding: 1em; overflow-x: auto; font-size: 12px; }\n"
      << ".stages { display: grid; grid-template-columns: repeat(auto-fill, minmax(420px, 1fr)); gap: 1.5em; }\n"
      // The width and height attributes give the aspect; CSS scales the width, height follows.
      << "figure { margin: 0; min-width: 0; } figure img { display: block; width: 100%; height: auto; "
      << "image-rendering: pixelated; border: 1px solid #333; box-sizing: border-box; }\n"
      << ".legend { font-size: 12px; color: #bbb; margin: 0.4em 0; }\n"
      << ".legend .bar { display: block; height: 12px; border: 1px solid #555; }\n"
      << ".legend .ticks { position: relative; height: 1.4em; }\n"
      << ".legend .ticks span { position: absolute; top: 2px; transform: translateX(-50%); white-space: nowrap; }\n"
      << ".legend .ticks span:first-child { transform: none; }\n"
      << ".legend .ticks span.end { transform: translateX(-100%); }\n"
      << ".legend .channel { display: flex; gap: 0.5em; align-items: center; margin: 2px 0; }\n"
      << ".legend .channel .name { width: 3.5em; } .legend .channel .bar { flex: 0 0 10em; display: inline-block; }\n"
      << ".legend .classes { display: flex; flex-wrap: wrap; gap: 0.3em 1em; margin-top: 0.2em; }\n"
      << ".legend .classes i { display: inline-block; width: 0.9em; height: 0.9em; border: 1px solid #777; "
      << "margin-right: 0.3em; vertical-align: -0.1em; }\n"
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
          << "\"></a>\n" << legend_html(stage_scale(s, rec, st.name)) << "<figcaption><b>" << html_escape(st.title)
          << " <code>(" << st.name << ")</code></b>" << html_escape(st.about) << "</figcaption></figure>\n";
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
