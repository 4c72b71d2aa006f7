// The HTTP server (cpp-httplib); see http_server.h.
#include "stepper/http_server.h"

#include <cctype>
#include <cstdio>
#include <ctime>
#include <map>
#include <mutex>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "stepper/explain.h"
#include "stepper/stages.h"
#include "stepper/web_assets.h"

namespace prast::stepper {

namespace {

using nlohmann::json;

// Limits against slow, idle and flooding clients (docs/security.md, "What
// `step --serve` lets in"): a connection must send something every kReadTimeoutSeconds, an
// idle keep-alive connection is closed after kKeepAliveSeconds, and one
// connection serves at most kKeepAliveRequests requests.
constexpr std::size_t kServerThreads = 16;
constexpr time_t kReadTimeoutSeconds = 2;
constexpr time_t kWriteTimeoutSeconds = 5;
constexpr time_t kKeepAliveSeconds = 2;
constexpr std::size_t kKeepAliveRequests = 20;
constexpr std::size_t kMaxBodyBytes = 4096;

// A request error: the status and a one-line message.
struct BadRequest {
    int status;
    std::string message;
};

void send_json(httplib::Response& res, const json& j, int status = 200) {
    res.status = status;
    // Invalid UTF-8 (a mesh name from a file) is replaced, never thrown.
    res.set_content(j.dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message) {
    send_json(res, json{{"error", message}}, status);
}

// An integer query parameter in [lo, hi].
long int_param(const httplib::Request& req, const char* name, long lo, long hi) {
    if (!req.has_param(name)) throw BadRequest{400, std::string("missing parameter '") + name + "'"};
    if (req.get_param_value_count(name) > 1) throw BadRequest{400, std::string("parameter '") + name + "' given twice"};
    const std::string v = req.get_param_value(name);
    long out = 0;
    if (!parse_int(v, lo, hi, out))
        throw BadRequest{400, std::string("parameter '") + name + "': expected an integer in " + std::to_string(lo) +
                                  ".." + std::to_string(hi)};
    return out;
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
bool cross_origin(const httplib::Request& req, int port) {
    if (req.has_header("Origin")) {
        const std::string origin = req.get_header_value("Origin"), p = ":" + std::to_string(port);
        if (origin != "http://127.0.0.1" + p && origin != "http://localhost" + p) return true;
    }
    if (req.has_header("Sec-Fetch-Site")) {
        const std::string site = req.get_header_value("Sec-Fetch-Site");
        if (site != "same-origin" && site != "none") return true;
    }
    return false;
}

} // namespace

int serve(Session& session, int port) {
    httplib::Server server;
    std::mutex mutex;  // the session and the recording are used by one request at a time
    std::map<std::string, std::string> png_cache;
    const Recording& rec = session.recording();
    FrameSetup& s = session.scene();

    // Runs a handler under the lock, turning bad requests into 4xx JSON.
    auto guarded = [&](auto handler) {
        return [&, handler](const httplib::Request& req, httplib::Response& res) {
            std::lock_guard<std::mutex> lock(mutex);
            try {
                handler(req, res);
            } catch (const BadRequest& e) {
                send_error(res, e.status, e.message);
            }
        };
    };
    auto send_png = [&](httplib::Response& res, const std::string& key, auto make) {
        auto it = png_cache.find(key);
        if (it == png_cache.end()) {
            if (png_cache.size() > 64) png_cache.clear();  // bound the memory of many slider positions
            const std::vector<std::uint8_t> png = make();
            it = png_cache.emplace(key, std::string(png.begin(), png.end())).first;
        }
        res.set_content(it->second, "image/png");
    };

    server.Get("/", [](const httplib::Request&, httplib::Response& res) {
        const WebAsset* a = find_web_asset("/index.html");
        res.set_content(reinterpret_cast<const char*>(a->data), a->size, a->mime);
    });
    server.Get(R"(/(index\.html|step\.js|step\.css))", [](const httplib::Request& req, httplib::Response& res) {
        const WebAsset* a = find_web_asset(req.path);
        if (!a) return send_error(res, 404, "not found");
        res.set_content(reinterpret_cast<const char*>(a->data), a->size, a->mime);
    });
    server.Get("/api/frame", guarded([&](const httplib::Request&, httplib::Response& res) {
        send_json(res, frame_json(s, rec));
    }));
    server.Get("/api/stages", guarded([&](const httplib::Request&, httplib::Response& res) {
        json list = json::array();
        for (const StageInfo& st : stage_list()) list.push_back({{"name", st.name}, {"title", st.title}, {"about", st.about}});
        send_json(res, list);
    }));
    server.Get("/api/stage", guarded([&](const httplib::Request& req, httplib::Response& res) {
        const std::string name = req.get_param_value("name");
        if (!find_stage(name)) throw BadRequest{404, "unknown stage (see /api/stages)"};
        send_png(res, "stage " + name, [&] { return session.stage_png(name); });
    }));
    server.Get("/api/upto", guarded([&](const httplib::Request& req, httplib::Response& res) {
        const long n = int_param(req, "n", 0, long(rec.triangle_count()));
        send_png(res, "upto " + std::to_string(n), [&] { return session.upto_png(std::uint64_t(n)); });
    }));
    server.Get("/api/pixel", guarded([&](const httplib::Request& req, httplib::Response& res) {
        const long x = int_param(req, "x", 0, rec.width - 1), y = int_param(req, "y", 0, rec.height - 1);
        send_json(res, pixel_json(s, rec, explain_pixel(s, rec, int(x), int(y))));
    }));
    server.Get("/api/tri", guarded([&](const httplib::Request& req, httplib::Response& res) {
        const long n = int_param(req, "n", 0, long(rec.triangle_count()) - 1);
        send_json(res, triangle_json(s, rec, std::uint32_t(n)));
    }));
    server.Get("/api/tile", guarded([&](const httplib::Request& req, httplib::Response& res) {
        const long x = int_param(req, "x", 0, rec.tiles_x - 1), y = int_param(req, "y", 0, rec.tiles_y - 1);
        send_json(res, tile_json(s, rec, int(x), int(y)));
    }));
    // Anything else: a JSON 404 (or the status httplib chose, e.g. 414 for a huge URI).
    server.set_error_handler([](const httplib::Request&, httplib::Response& res) {
        if (res.body.empty()) send_error(res, res.status == 200 ? 404 : res.status,
                                         res.status == 404 ? "not found" : "bad request");
    });
    server.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "internal error";
        try {
            if (ep) std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            what = e.what();
        } catch (...) {
        }
        send_error(res, 500, what);
    });
    server.set_payload_max_length(kMaxBodyBytes);
    // Idle and slow connections (a browser's keep-alive, a stalled client)
    // hold a worker only briefly; more workers than cores, because requests
    // wait for the session's lock anyway and a stalled socket costs no CPU.
    server.set_read_timeout(kReadTimeoutSeconds, 0);
    server.set_write_timeout(kWriteTimeoutSeconds, 0);
    server.set_keep_alive_timeout(kKeepAliveSeconds);
    server.set_keep_alive_max_count(kKeepAliveRequests);
    server.new_task_queue = [] { return new httplib::ThreadPool(kServerThreads); };
    // Responses are never sniffed as another type, never framed, never
    // cached; the page loads only its own files (no inline script, no CDN).
    server.set_default_headers({
        {"X-Content-Type-Options", "nosniff"},
        {"Cache-Control", "no-store"},
        {"Referrer-Policy", "no-referrer"},
        {"Content-Security-Policy", "default-src 'self'; img-src 'self'; style-src 'self'; script-src 'self'; "
                                    "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'"},
    });

    int bound = port;
    if (port == 0) bound = server.bind_to_any_port("127.0.0.1");
    else if (!server.bind_to_port("127.0.0.1", port)) bound = -1;
    if (bound <= 0) {
        std::fprintf(stderr, "step: cannot listen on 127.0.0.1:%d (in use? try --port 0)\n", port);
        return 1;
    }
    // Before any route: our Host names only, read-only methods, no body
    // (httplib does not read a GET's body, so it would be parsed as the
    // next request on the connection).
    server.set_pre_routing_handler([bound](const httplib::Request& req, httplib::Response& res) {
        if (req.get_header_value_count("Host") != 1 || !host_allowed(req.get_header_value("Host"), bound)) {
            send_error(res, 403, "the Host header must be 127.0.0.1 or localhost (with this server's port)");
        } else if (cross_origin(req, bound)) {
            send_error(res, 403, "a request from another site's page");
        } else if (req.method != "GET" && req.method != "HEAD") {
            res.set_header("Allow", "GET, HEAD");
            send_error(res, 405, "read-only: only GET and HEAD");
        } else if (req.has_header("Transfer-Encoding") ||
                   (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0")) {
            send_error(res, 400, "a GET request has no body");
        } else {
            return httplib::Server::HandlerResponse::Unhandled;
        }
        return httplib::Server::HandlerResponse::Handled;
    });
    std::printf("step: serving http://127.0.0.1:%d/ (Ctrl-C to stop)\n", bound);
    std::fflush(stdout);
    server.listen_after_bind();
    return 0;
}

} // namespace prast::stepper
