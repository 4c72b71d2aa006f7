// render's command line as a frame request (renderer/frame_setup.h): the one
// translation render, step and llvmpipe-render share, so that the same flags
// give the same frame in each.
#pragma once

#include "apps/render_options.h"
#include "renderer/frame_setup.h"

namespace prast {

// The frame `render` draws for these options.
inline FrameRequest render_frame_request(const RenderOptions& opt) {
    FrameRequest r;
    r.scene = opt.scene;
    r.allow_outside_paths = opt.allow_outside_paths;
    r.width = opt.width;
    r.height = opt.height;
    r.eye = opt.eye;
    r.target = opt.target;
    r.up = opt.up;
    r.fov_deg = opt.fov_deg;
    r.near_plane = opt.near_plane;
    r.far_plane = opt.far_plane;
    r.lights = opt.lights;
    r.ambient = opt.ambient;
    r.ambient_given = opt.ambient_given;
    r.file_lights = opt.file_lights;
    r.no_default_lights = opt.no_default_lights;
    r.brdf = opt.brdf;
    r.env = opt.env;
    r.env_intensity = opt.env_intensity;
    r.env_rotate_deg = opt.env_rotate_deg;
    // The reference integral (--ibl reference, and --pixel's) samples the map.
    r.env_importance_sampling = opt.ibl == IblMode::Reference || opt.pixel.has_value();
    r.ibl = opt.ibl;
    r.ibl_samples = opt.ibl_samples;
    r.background = opt.background;
    r.background_color = opt.background_color;
    r.energy = opt.energy;
    r.view = opt.view;
    r.samples = opt.msaa;
    r.shadows = opt.shadows;
    r.exposure = opt.exposure;
    r.tonemap = opt.effective_tonemap();
    r.threads = opt.threads;
    r.tile_size = opt.tile_size;
    r.bytes_per_pixel = kBytesPerPixel;
    r.time = opt.time;
    r.animation = opt.animation;
    r.camera = opt.camera;
    r.variant = opt.variant;
    r.fps = opt.fps;
    // A turntable (render.cpp: frames orbit unless --fps without --orbit).
    if (opt.frames > 1 && (opt.fps <= 0.0 || opt.orbit_given)) r.orbit_deg = opt.orbit_deg;
    return r;
}

// Where and how `render` writes the 8-bit image of a frame for these
// options: exposure, tone map, data views raw; the linear colour and depth
// kept only for --pixel, which reads them.
inline ImageOutput render_image_output(const RenderOptions& opt, std::uint8_t* rgba8) {
    ImageOutput out;
    out.rgba8 = rgba8;
    out.exposure = opt.exposure;
    out.tonemap = opt.effective_tonemap();
    out.raw = debug_view_is_data(opt.view);
    out.keep_framebuffer = opt.pixel.has_value();
    return out;
}

// The frame `step` records for these options: render's frame 0, with the
// recording in the memory plan. step explains the split sum (its --pixel is
// not render's reference probe) and prints every warning.
inline FrameRequest step_frame_request(const RenderOptions& opt) {
    FrameRequest r = render_frame_request(opt);
    r.env_importance_sampling = false;
    r.recording = true;
    r.cap_warnings = false;
    return r;
}

} // namespace prast
