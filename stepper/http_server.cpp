// The routes of `step --serve` and the checks every request passes; the
// connections and their limits are http_connections.h's, the bytes
// http_wire.h's. See http_server.h.
#include "stepper/http_server.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "stepper/explain.h"
#include "stepper/http_connections.h"
#include "stepper/stages.h"
#include "stepper/views.h"
#include "stepper/web_assets.h"

namespace prast::stepper {

namespace {

using nlohmann::json;

// A request error: the status and a one-line message.
struct BadRequest {
    int status;
    std::string message;
};

HttpResponse json_response(const json& j, int status = 200) {
    HttpResponse res;
    res.status = status;
    res.content_type = "application/json";
    // Invalid UTF-8 (a mesh name from a file) is replaced, never thrown.
    res.body = j.dump(-1, ' ', false, json::error_handler_t::replace);
    return res;
}

HttpResponse error_response(int status, const std::string& message) {
    return json_response(json{{"error", message}}, status);
}

// A refusal before any route: the connection is closed after it (a body
// it announced is never read).
HttpResponse refusal(int status, const std::string& message) {
    HttpResponse res = error_response(status, message);
    res.close = true;
    return res;
}

// An integer query parameter in [lo, hi]; `what` names it in the message
// ("triangle number 'n' must be in 0..98431 (the frame has 98432
// triangles)"), which holds the frame's numbers, never the request's.
long int_param(const HttpRequest& req, const char* name, long lo, long hi, const std::string& what,
               const std::string& why) {
    if (!req.param_count(name)) throw BadRequest{400, std::string("missing parameter '") + name + "'"};
    if (req.param_count(name) > 1) throw BadRequest{400, std::string("parameter '") + name + "' given twice"};
    long out = 0;
    if (!parse_int(req.param(name), lo, hi, out))
        throw BadRequest{400, what + " '" + name + "' must be in " + std::to_string(lo) + ".." + std::to_string(hi) +
                                  " (" + why + ")"};
    return out;
}

// The texture the request's one 'id' names among the frame's (filled into
// `all`, which the result points into).
const TextureInfo& texture_param(const HttpRequest& req, const FrameSetup& s, const Recording& rec, TexturesView& all) {
    if (!make_textures(s, rec, all).empty()) throw BadRequest{500, "the textures cannot be listed"};
    if (req.param_count("id") != 1) throw BadRequest{400, "parameter 'id': one texture ID (see /api/textures)"};
    for (const TextureInfo& t : all.textures)
        if (t.id == req.param("id")) return t;
    throw BadRequest{404, "unknown texture ID (see /api/textures)"};
}

bool equals_lower(const std::string& s, const char* lower) {
    std::size_t i = 0;
    for (; i < s.size() && lower[i]; ++i)
        if (std::tolower(static_cast<unsigned char>(s[i])) != lower[i]) return false;
    return i == s.size() && !lower[i];
}

// DNS rebinding: a page on the web whose name resolves to 127.0.0.1 reaches
// this server with its own name in Host; only our names are accepted (with
// no port or ours).
bool host_allowed(const std::string& host, int port) {
    std::string name = host;
    const std::size_t colon = host.rfind(':');
    if (colon != std::string::npos) {
        if (host.substr(colon + 1) != std::to_string(port)) return false;
        name = host.substr(0, colon);
    }
    return name == "127.0.0.1" || equals_lower(name, "localhost");
}

// A request a browser made for another origin's page (an <img>, a form, a
// fetch from a site, or from another server on this machine): browsers name
// the page's origin in Origin and say in Sec-Fetch-Site whether it is ours.
// Requests from our page or typed in the address bar pass; so do clients
// that send neither (curl, scripts).
bool cross_origin(const HttpRequest& req, int port) {
    const std::string p = ":" + std::to_string(port);
    for (const auto& [name, value] : req.headers) {
        if (name == "origin" && value != "http://127.0.0.1" + p && value != "http://localhost" + p) return true;
        if (name == "sec-fetch-site" && value != "same-origin" && value != "none") return true;
    }
    return false;
}

bool is_other_method(const std::string& m) {
    for (const char* known : {"POST", "PUT", "DELETE", "PATCH", "OPTIONS", "TRACE", "CONNECT"})
        if (m == known) return true;
    return false;
}

HttpResponse asset_response(const WebAsset& a) {
    HttpResponse res;
    res.content_type = a.mime;
    res.body.assign(reinterpret_cast<const char*>(a.data), a.size);
    return res;
}

// The tab's icon, drawn here: a 16x16 ICO (one 32-bit BMP image) holding an
// orange triangle, so a browser's request for /favicon.ico is answered.
std::string make_favicon() {
    constexpr int kSide = 16;
    std::string ico;
    auto u16 = [&](unsigned v) { ico += char(v & 0xff); ico += char(v >> 8); };
    auto u32 = [&](std::uint32_t v) { u16(v & 0xffff); u16(v >> 16); };
    const std::uint32_t image_bytes = 40 + kSide * kSide * 4 + kSide * 4;  // header, BGRA, AND mask
    u16(0); u16(1); u16(1);                                    // ICONDIR: an icon, one image
    ico += char(kSide); ico += char(kSide); ico += '\0'; ico += '\0';
    u16(1); u16(32); u32(image_bytes); u32(22);                // ICONDIRENTRY
    u32(40); u32(kSide); u32(2 * kSide); u16(1); u16(32);      // BITMAPINFOHEADER (height: image and mask)
    for (int i = 0; i < 6; ++i) u32(0);
    // Pixel centres inside the triangle (1,14) (15,14) (8,1), rows bottom-up.
    auto edge = [](double ax, double ay, double bx, double by, double px, double py) {
        return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
    };
    for (int row = kSide - 1; row >= 0; --row)
        for (int col = 0; col < kSide; ++col) {
            const double px = col + 0.5, py = row + 0.5;
            const bool inside = edge(1, 14, 15, 14, px, py) <= 0 && edge(15, 14, 8, 1, px, py) <= 0 &&
                                edge(8, 1, 1, 14, px, py) <= 0;
            const char bgra[4] = {char(0x20), char(0x78), char(0xe8), char(inside ? 0xff : 0)};
            ico.append(bgra, 4);
        }
    ico.append(kSide * 4, '\0');  // the AND mask: unused with alpha
    return ico;
}

} // namespace

int serve(Session& session, int port) {
    std::mutex mutex;  // the session and the recording are used by one request at a time
    std::map<std::string, std::string> png_cache;
    const Recording& rec = session.recording();
    FrameSetup& s = session.scene();

    std::string error;
    int bound = 0;
    const int listen_fd = listen_loopback(port, bound, error);
    if (listen_fd < 0) {
        std::fprintf(stderr, "step: %s\n", error.c_str());
        return 1;
    }

    const std::string triangles = std::to_string(rec.triangle_count());
    const std::string frame_has = "the frame has " + triangles + " triangles";
    const std::string image_is = "the image is " + std::to_string(rec.width) + "x" + std::to_string(rec.height);
    const std::string tiles_are =
        "the frame has " + std::to_string(rec.tiles_x) + "x" + std::to_string(rec.tiles_y) + " tiles";
    auto png_response = [&](const std::string& key, auto make) {
        auto it = png_cache.find(key);
        if (it == png_cache.end()) {
            if (png_cache.size() > 64) png_cache.clear();  // bound the memory of many slider positions
            const std::vector<std::uint8_t> png = make();
            it = png_cache.emplace(key, std::string(png.begin(), png.end())).first;
        }
        HttpResponse res;
        res.content_type = "image/png";
        res.body = it->second;
        return res;
    };
    // The API: one request at a time, on the session.
    auto api = [&](const HttpRequest& req) -> HttpResponse {
        const std::string& path = req.path;
        if (path == "/api/frame") return json_response(frame_json(s, rec));
        if (path == "/api/stages") return json_response(stage_list_json(s, rec));
        if (path == "/api/stage") {
            const std::string name = req.param("name");
            if (!find_stage(name)) throw BadRequest{404, "unknown stage (see /api/stages)"};
            return png_response("stage " + name, [&] { return session.stage_png(name); });
        }
        if (path == "/api/upto") {
            const long n = int_param(req, "n", 0, long(rec.triangle_count()), "triangle count", frame_has);
            return png_response("upto " + std::to_string(n), [&] { return session.upto_png(std::uint64_t(n)); });
        }
        if (path == "/api/pixel") {
            const long x = int_param(req, "x", 0, rec.width - 1, "pixel column", image_is);
            const long y = int_param(req, "y", 0, rec.height - 1, "pixel row", image_is);
            // The slider's point (`upto N`); without it, the frame's end.
            std::uint64_t upto = kAllTriangles;
            if (req.param_count("upto"))
                upto = std::uint64_t(int_param(req, "upto", 0, long(rec.triangle_count()), "triangle count", frame_has));
            return json_response(pixel_json(s, rec, session.explain(int(x), int(y), upto)));
        }
        if (path == "/api/tri") {
            const long n = int_param(req, "n", 0, long(rec.triangle_count()) - 1, "triangle number", frame_has);
            return json_response(triangle_json(s, rec, std::uint32_t(n)));
        }
        if (path == "/api/tile") {
            const long x = int_param(req, "x", 0, rec.tiles_x - 1, "tile column", tiles_are);
            const long y = int_param(req, "y", 0, rec.tiles_y - 1, "tile row", tiles_are);
            return json_response(tile_json(s, rec, int(x), int(y)));
        }
        // The views (stepper/views.h), with the terminal's numbers. Every
        // parameter is checked here, so an error never repeats the request.
        const std::string draws_are = "the frame has " + std::to_string(rec.draws.size()) + " draws";
        if (path == "/api/draws") {
            DrawsView v;
            if (!make_draws(s, rec, v).empty()) throw BadRequest{500, "the draws cannot be listed"};
            return json_response(v.json());
        }
        if (path == "/api/draw") {
            const long n = int_param(req, "n", 0, long(rec.draws.size()) - 1, "draw number", draws_are);
            DrawView v;
            if (!make_draw(s, rec, std::to_string(n), v).empty()) throw BadRequest{500, "the draw cannot be shown"};
            return json_response(v.json());
        }
        if (path == "/api/textures") {
            TexturesView v;
            if (!make_textures(s, rec, v).empty()) throw BadRequest{500, "the textures cannot be listed"};
            return json_response(v.json());
        }
        if (path == "/api/texture" || path == "/api/texture.png") {
            // The ID among the frame's; the level among its levels.
            TexturesView all;
            const TextureInfo* info = &texture_param(req, s, rec, all);
            long level = 0;
            if (req.param_count("level"))
                level = int_param(req, "level", 0, info->levels - 1, "mip level",
                                  "the texture has " + std::to_string(info->levels) + " levels");
            const std::string id = info->id, lv = std::to_string(level);
            if (path == "/api/texture") {
                TextureView v;
                if (!make_texture(s, rec, id, lv, v).empty()) throw BadRequest{500, "the texture cannot be shown"};
                return json_response(v.json());
            }
            return png_response("texture " + id + " " + lv, [&] {
                std::vector<std::uint8_t> png;
                if (!texture_png(s, rec, id, lv, png).empty()) throw BadRequest{500, "the texture cannot be drawn"};
                return png;
            });
        }
        if (path == "/api/texel") {
            // As /api/texture: the ID among the frame's, the level among its
            // levels, then x and y inside that level.
            TexturesView all;
            const TextureInfo* info = &texture_param(req, s, rec, all);
            const long level = int_param(req, "level", 0, info->levels - 1, "mip level",
                                         "the texture has " + std::to_string(info->levels) + " levels");
            const glm::ivec2 size = info->level_sizes[std::size_t(level)];
            const std::string has = "the level is " + std::to_string(size.x) + "x" + std::to_string(size.y);
            const long x = int_param(req, "x", 0, size.x - 1, "texel column", has);
            const long y = int_param(req, "y", 0, size.y - 1, "texel row", has);
            TexelView v;
            if (!make_texel(s, rec, info->id, std::to_string(level), std::to_string(x), std::to_string(y), v).empty())
                throw BadRequest{500, "the texel cannot be shown"};
            return json_response(v.json());
        }
        if (path == "/api/vertices") {
            const long d = int_param(req, "draw", 0, long(rec.draws.size()) - 1, "draw number", draws_are);
            const long count_all = long(rec.draws[std::size_t(d)].vertex_count);
            const std::string has = "the draw has " + std::to_string(count_all) + " vertices";
            long first = 0, count = kDefaultVertexRows;
            if (req.param_count("first"))
                first = int_param(req, "first", 0, std::max(0L, count_all - 1), "first vertex", has);
            if (req.param_count("count"))
                count = int_param(req, "count", 1, kMaxVertexRows, "vertex count",
                                  "at most " + std::to_string(kMaxVertexRows) + " rows");
            VerticesView v;
            if (!make_vertices(s, rec, std::to_string(d), std::to_string(first), std::to_string(count), v).empty())
                throw BadRequest{400, "the vertices cannot be shown (see /api/draws)"};
            return json_response(v.json());
        }
        return error_response(404, "not found");
    };
    const std::string favicon = make_favicon();

    HttpApp app;
    app.handle = [&](const HttpRequest& req) -> HttpResponse {
        // Before any route: our Host names only, read-only methods, no
        // body, no ranges (a Range header asking for the same bytes
        // thousands of times would multiply the answer).
        if (req.header_count("host") != 1 || !host_allowed(req.header("host"), bound))
            return refusal(403, "the Host header must be 127.0.0.1 or localhost (with this server's port)");
        if (cross_origin(req, bound)) return refusal(403, "a request from another site's page");
        if (req.method != "GET" && req.method != "HEAD") {
            if (!is_other_method(req.method)) return refusal(400, "unknown method");
            HttpResponse res = refusal(405, "read-only: only GET and HEAD");
            res.headers.emplace_back("Allow", "GET, HEAD");
            return res;
        }
        if (req.header_count("transfer-encoding") ||
            (req.header_count("content-length") && (req.header_count("content-length") > 1 ||
                                                    req.header("content-length") != "0")))
            return refusal(400, "a GET request has no body");
        if (req.header_count("range")) return refusal(416, "range requests are not served");

        // The page's files, built in, by exact name.
        if (req.path == "/") return asset_response(*find_web_asset("/index.html"));
        if (req.path == "/index.html" || req.path == "/step.js" || req.path == "/step.css") {
            const WebAsset* a = find_web_asset(req.path);
            return a ? asset_response(*a) : error_response(404, "not found");
        }
        if (req.path == "/favicon.ico") {
            HttpResponse res;
            res.content_type = "image/x-icon";
            res.body = favicon;
            return res;
        }
        if (req.path.compare(0, 5, "/api/") != 0) return error_response(404, "not found");
        std::lock_guard<std::mutex> lock(mutex);
        try {
            return api(req);
        } catch (const BadRequest& e) {
            return error_response(e.status, e.message);
        } catch (const std::exception& e) {
            return error_response(500, e.what());
        }
    };
    app.refuse = [](int status, const char* message) { return refusal(status, message); };
    // Responses are never sniffed as another type, never framed, never
    // cached; the page loads only its own files (no inline script, no CDN).
    app.common_headers =
        "X-Content-Type-Options: nosniff\r\n"
        "Cache-Control: no-store\r\n"
        "Referrer-Policy: no-referrer\r\n"
        "Content-Security-Policy: default-src 'self'; img-src 'self'; style-src 'self'; script-src 'self'; "
        "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'\r\n";

    std::printf("step: serving http://127.0.0.1:%d/ (Ctrl-C to stop)\n", bound);
    std::fflush(stdout);
    return serve_connections(listen_fd, app);
}

} // namespace prast::stepper
