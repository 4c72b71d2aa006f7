// Request heads and status lines; see http_wire.h.
#include "stepper/http_wire.h"

#include <cstring>

namespace prast::stepper {

namespace {

bool is_token_char(unsigned char c) {
    if ((c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')) return true;
    return c && std::strchr("!#$%&'*+-.^_`|~", c) != nullptr;
}

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// %XX decoding (and '+' as a space in a query); false on a broken escape.
bool percent_decode(std::string_view in, bool plus_is_space, std::string& out) {
    out.clear();
    for (std::size_t i = 0; i < in.size(); ++i) {
        if (in[i] == '%') {
            if (i + 2 >= in.size()) return false;
            const int hi = hex_value(in[i + 1]), lo = hex_value(in[i + 2]);
            if (hi < 0 || lo < 0) return false;
            out += char(hi * 16 + lo);
            i += 2;
        } else {
            out += plus_is_space && in[i] == '+' ? ' ' : in[i];
        }
    }
    return true;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

const std::string kEmpty;

} // namespace

HeadScanner::State HeadScanner::fail(int status, const char* message) {
    state_ = State::error;
    error_status_ = status;
    error_message_ = message;
    return state_;
}

HeadScanner::State HeadScanner::feed(std::string_view buf) {
    while (state_ == State::more && pos_ < buf.size()) {
        const bool request_line = lines_ == 0;
        const std::size_t limit = request_line ? kMaxRequestLineBytes : kMaxHeaderLineBytes;
        const int long_status = request_line ? 414 : 431;
        const char* long_message = request_line ? "request line too long (over 8192 bytes)"
                                                : "header line too long (over 8192 bytes)";
        const void* nl = std::memchr(buf.data() + pos_, '\n', buf.size() - pos_);
        if (!nl) {
            // The line so far (a CR at its end may be half of its CR LF).
            if (buf.size() - line_start_ > limit + 1) return fail(long_status, long_message);
            if (buf.size() > kMaxHeadBytes) return fail(431, "request head too long (over 16384 bytes)");
            pos_ = buf.size();
            return state_;
        }
        const std::size_t end = std::size_t(static_cast<const char*>(nl) - buf.data());
        if (end == line_start_ || buf[end - 1] != '\r') return fail(400, "a line of the request does not end in CR LF");
        const std::size_t length = end - 1 - line_start_;
        if (length > limit) return fail(long_status, long_message);
        if (end + 1 > kMaxHeadBytes) return fail(431, "request head too long (over 16384 bytes)");
        pos_ = line_start_ = end + 1;
        if (length == 0) {
            if (request_line) return fail(400, "the request starts with an empty line");
            state_ = State::complete;
            return state_;
        }
        if (++lines_ > kMaxHeaderLines + 1) return fail(431, "too many header lines (over 100)");
    }
    return state_;
}

bool parse_request_head(std::string_view head, HttpRequest& out, const char*& error) {
    out = HttpRequest();
    error = "malformed request";
    std::vector<std::string_view> lines;
    for (std::size_t start = 0; start < head.size();) {
        const std::size_t end = head.find("\r\n", start);
        if (end == std::string_view::npos) return false;
        if (end == start) break;  // the blank line
        lines.push_back(head.substr(start, end - start));
        start = end + 2;
    }
    if (lines.empty()) return false;
    for (std::string_view line : lines)
        if (line.find('\r') != std::string_view::npos || line.find('\n') != std::string_view::npos) {
            error = "a line of the request does not end in CR LF";
            return false;
        }

    // METHOD SP target SP HTTP/1.x, single spaces.
    const std::string_view rl = lines[0];
    const std::size_t sp1 = rl.find(' ');
    const std::size_t sp2 = sp1 == std::string_view::npos ? sp1 : rl.find(' ', sp1 + 1);
    if (sp2 == std::string_view::npos || rl.find(' ', sp2 + 1) != std::string_view::npos) {
        error = "malformed request line";
        return false;
    }
    const std::string_view method = rl.substr(0, sp1), target = rl.substr(sp1 + 1, sp2 - sp1 - 1),
                           version = rl.substr(sp2 + 1);
    if (method.empty() || method.size() > 16) {
        error = "malformed request line";
        return false;
    }
    for (char c : method)
        if (c < 'A' || c > 'Z') {
            error = "malformed method";
            return false;
        }
    if (version != "HTTP/1.1" && version != "HTTP/1.0") {
        error = "only HTTP/1.0 and HTTP/1.1";
        return false;
    }
    if (target.empty() || target[0] != '/') {
        error = "the request target must be a path";
        return false;
    }
    for (char c : target)
        if (static_cast<unsigned char>(c) < 0x21 || static_cast<unsigned char>(c) > 0x7e) {
            error = "a byte the request target may not hold";
            return false;
        }
    out.method = std::string(method);
    out.http10 = version == "HTTP/1.0";

    // The path, then the query's name=value pairs (empty ones skipped).
    const std::size_t q = target.find('?');
    error = "malformed percent-encoding";
    if (!percent_decode(target.substr(0, q), false, out.path)) return false;
    if (q != std::string_view::npos) {
        std::string_view query = target.substr(q + 1);
        while (!query.empty()) {
            const std::size_t amp = query.find('&');
            const std::string_view pair = query.substr(0, amp);
            query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
            if (pair.empty()) continue;
            const std::size_t eq = pair.find('=');
            std::string name, value;
            if (!percent_decode(pair.substr(0, eq), true, name)) return false;
            if (eq != std::string_view::npos && !percent_decode(pair.substr(eq + 1), true, value)) return false;
            out.params.emplace_back(std::move(name), std::move(value));
        }
    }

    // name: value, the name a token (no space before the colon), no folded lines.
    for (std::size_t i = 1; i < lines.size(); ++i) {
        const std::string_view line = lines[i];
        const std::size_t colon = line.find(':');
        if (colon == 0 || colon == std::string_view::npos) {
            error = "malformed header line";
            return false;
        }
        std::string name(line.substr(0, colon));
        for (char& c : name) {
            if (!is_token_char(static_cast<unsigned char>(c))) {
                error = "malformed header name";
                return false;
            }
            if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
        }
        const std::string_view value = trim(line.substr(colon + 1));
        for (char c : value)
            if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f) {
                error = "a control character in a header";
                return false;
            }
        out.headers.emplace_back(std::move(name), std::string(value));
    }
    return true;
}

std::size_t HttpRequest::header_count(std::string_view lower_name) const {
    std::size_t n = 0;
    for (const auto& [k, v] : headers) n += k == lower_name;
    return n;
}

const std::string& HttpRequest::header(std::string_view lower_name) const {
    for (const auto& [k, v] : headers)
        if (k == lower_name) return v;
    return kEmpty;
}

std::size_t HttpRequest::param_count(std::string_view name) const {
    std::size_t n = 0;
    for (const auto& [k, v] : params) n += k == name;
    return n;
}

const std::string& HttpRequest::param(std::string_view name) const {
    for (const auto& [k, v] : params)
        if (k == name) return v;
    return kEmpty;
}

std::string status_line(int status) {
    const char* reason = "Error";
    switch (status) {
    case 200: reason = "OK"; break;
    case 204: reason = "No Content"; break;
    case 400: reason = "Bad Request"; break;
    case 403: reason = "Forbidden"; break;
    case 404: reason = "Not Found"; break;
    case 405: reason = "Method Not Allowed"; break;
    case 414: reason = "URI Too Long"; break;
    case 416: reason = "Range Not Satisfiable"; break;
    case 431: reason = "Request Header Fields Too Large"; break;
    case 500: reason = "Internal Server Error"; break;
    case 503: reason = "Service Unavailable"; break;
    }
    return "HTTP/1.1 " + std::to_string(status) + " " + reason + "\r\n";
}

} // namespace prast::stepper
