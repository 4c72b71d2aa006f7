// The bytes of HTTP/1.1 for `step --serve`: finding the end of a request's
// head as it arrives (with the size limits checked on every byte, so a
// flood is refused after 16 KiB, not after it ends), parsing a complete
// head strictly, and writing a response's head. No sockets here
// (http_connections.h has them); everything is a plain function of bytes.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace prast::stepper {

// Limits on a request's head (docs/security.md, "What `step --serve` lets in").
constexpr std::size_t kMaxRequestLineBytes = 8192;   // beyond: 414
constexpr std::size_t kMaxHeaderLineBytes = 8192;    // beyond: 431
constexpr std::size_t kMaxHeaderLines = 100;         // beyond: 431
constexpr std::size_t kMaxHeadBytes = 16384;         // request line, headers and the blank line; beyond: 431

// Watches a request's head arrive. feed() looks at the bytes not seen yet;
// once the blank line is found, head_bytes() is the head's length (the
// rest of the buffer is the next request, pipelined).
class HeadScanner {
public:
    enum class State { more, complete, error };
    State feed(std::string_view buffer);
    std::size_t head_bytes() const { return pos_; }
    int error_status() const { return error_status_; }       // 400, 414 or 431
    const char* error_message() const { return error_message_; }
    void reset() { *this = HeadScanner(); }

private:
    State fail(int status, const char* message);
    std::size_t pos_ = 0;         // bytes looked at
    std::size_t line_start_ = 0;
    std::size_t lines_ = 0;       // complete lines, the request line included
    State state_ = State::more;
    int error_status_ = 0;
    const char* error_message_ = "";
};

struct HttpRequest {
    std::string method;   // "GET"
    std::string path;     // percent-decoded, without the query
    bool http10 = false;  // HTTP/1.0: no keep-alive
    std::vector<std::pair<std::string, std::string>> params;   // the query, decoded, in order
    std::vector<std::pair<std::string, std::string>> headers;  // names lower-cased, values trimmed

    std::size_t header_count(std::string_view lower_name) const;
    // The first such header's value ("" when there is none).
    const std::string& header(std::string_view lower_name) const;
    std::size_t param_count(std::string_view name) const;
    const std::string& param(std::string_view name) const;
};

// Parses a complete head (what HeadScanner found, blank line included).
// On failure: false, with a 400 and a fixed message (never the request's bytes).
bool parse_request_head(std::string_view head, HttpRequest& out, const char*& error_message);

// "HTTP/1.1 404 Not Found\r\n"
std::string status_line(int status);

} // namespace prast::stepper
