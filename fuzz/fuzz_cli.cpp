// libFuzzer harness: render's command-line parser (apps/render_options.h).
// The input is the argument list, split at NUL bytes. Besides not crashing,
// a successful parse must leave options render can use as they are: the
// invariants below trap when it does not.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "apps/render_options.h"

namespace {

bool within(const std::optional<glm::vec3>& v) {
    return !v || (std::fabs(v->x) <= prast::kMaxCameraCoordinate && std::fabs(v->y) <= prast::kMaxCameraCoordinate &&
                  std::fabs(v->z) <= prast::kMaxCameraCoordinate);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<std::string> args = {"render"};
    std::string cur;
    for (std::size_t i = 0; i < size && args.size() < 64; ++i) {
        if (data[i] == 0) {
            args.push_back(cur);
            cur.clear();
        } else {
            cur += char(data[i]);
        }
    }
    if (!cur.empty()) args.push_back(cur);
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());

    prast::RenderOptions o;
    const std::string err = prast::parse_render_args(int(argv.size()), argv.data(), o, std::uint64_t(8) << 30);
    if (!err.empty() || o.help || o.version) return 0;

    // What render relies on after a successful parse.
    if (o.width < 1 || o.height < 1 || o.width > prast::kMaxViewportSize || o.height > prast::kMaxViewportSize)
        __builtin_trap();
    if (!(o.fov_deg >= prast::kMinFovDeg && o.fov_deg < 180.0f)) __builtin_trap();
    if (o.frames < 1 || o.first_frame < 0 || o.first_frame > o.last_frame || o.last_frame >= o.frames) __builtin_trap();
    if (o.threads < 0 || o.threads > prast::kMaxThreads || o.repeat < 1) __builtin_trap();
    if (o.tile_size < prast::kMinTileSize || o.tile_size > prast::kMaxTileSize) __builtin_trap();
    if (!within(o.eye) || !within(o.target)) __builtin_trap();
    if (!std::isfinite(o.exposure) || !(o.exposure > 0.0f) || !std::isfinite(o.orbit_deg)) __builtin_trap();
    if (o.near_plane && o.far_plane && !(*o.near_plane < *o.far_plane)) __builtin_trap();
    const prast::render_cli::FramePattern pattern(o.output);
    if (!pattern.error.empty() || (o.frames > 1 && !pattern.has_number)) __builtin_trap();
    if (pattern.format(o.first_frame).empty() || pattern.format(o.last_frame).empty()) __builtin_trap();
    if (o.pixel && (o.pixel->x >= o.width || o.pixel->y >= o.height)) __builtin_trap();
    return 0;
}
