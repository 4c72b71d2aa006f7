// The command interpreter of `step`: one command line in, its text out.
// The terminal front end feeds it standard input; the web server calls it
// (and the JSON forms in explain.h) for each request. Bad commands get a
// one-line "error: ..." and the session goes on.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "stepper/explain.h"
#include "stepper/recording.h"

namespace prast::stepper {

struct Reply {
    bool ok = true;
    bool quit = false;
    std::string text;   // lines ending in '\n'; an error is one line "error: ..."
};

class Session {
public:
    Session(FrameSetup& scene, Recording& rec) : s_(scene), rec_(rec) {}

    Reply run(const std::string& line);

    // The PNG bytes of a stage, or of the frame after the first n triangles.
    std::vector<std::uint8_t> stage_png(const std::string& name);
    std::vector<std::uint8_t> upto_png(std::uint64_t triangles);
    std::vector<std::uint8_t> upto_rgba(std::uint64_t triangles);
    // The frame after the first n triangles, kept until another n is asked
    // for (the page's slider asks for its image, then for its pixels).
    const Framebuffer& upto_frame(std::uint64_t triangles);
    // Pixel X Y explained after the first `upto` triangles (kAllTriangles,
    // or the frame's count or more: at the frame's end).
    PixelExplanation explain(int x, int y, std::uint64_t upto);
    // Where `pixel` explains: set by `upto N`, back to the end by `upto all`.
    std::uint64_t upto() const { return upto_; }

    FrameSetup& scene() { return s_; }
    const Recording& recording() const { return rec_; }

private:
    Reply help() const;
    // The views of views.h (draws, draw, textures, texture, vertices, tile):
    // their text, or with as_json their JSON on one line.
    Reply run_view(const std::string& line, bool as_json);
    // The commands after the views.
    Reply run_rest(const std::vector<std::string>& words);
    Reply cost();
    Reply verify();

    FrameSetup& s_;
    Recording& rec_;
    std::uint64_t upto_ = kAllTriangles;
    std::uint64_t frame_upto_ = kAllTriangles;  // what frame_ holds; kAllTriangles: nothing yet
    Framebuffer frame_;
};

// Splits a command line at spaces and tabs.
std::vector<std::string> split_words(const std::string& line);
// A whole word as an integer in [lo, hi].
bool parse_int(const std::string& word, long lo, long hi, long& out);

} // namespace prast::stepper
