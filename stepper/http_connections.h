// The connections behind `step --serve`: the listening socket (127.0.0.1
// only, one server per port), one event thread that accepts connections and
// reads request heads under the limits of http_wire.h and the deadlines
// below, and a few worker threads that answer complete requests. A
// connection costs a worker only while its answer is made (the event thread
// writes what the socket does not take at once), so idle, stalled and
// trickling clients (slow-loris) and clients that do not read their answers
// hold no worker; at the connection cap the oldest connection not being
// answered is closed to let a new one in. Numbers are in docs/security.md.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "stepper/http_wire.h"

namespace prast::stepper {

constexpr std::size_t kHttpWorkers = 4;
constexpr std::size_t kMaxConnections = 1024;        // fewer when the fd limit is lower
constexpr int kListenBacklog = 512;                  // the kernel caps it at net.core.somaxconn
constexpr std::chrono::milliseconds kKeepAliveIdle{2000};    // a connection without a request yet
constexpr std::chrono::milliseconds kReadIdle{2000};         // silence within a request's head
constexpr std::chrono::milliseconds kRequestDeadline{5000};  // a whole head, from its first byte
constexpr std::chrono::milliseconds kWriteIdle{5000};        // a client that stops reading its answer
constexpr std::chrono::milliseconds kWriteDeadline{10000};   // a whole answer
constexpr std::size_t kMaxPendingBytes = 16u << 20;          // answers waiting for their clients to read
constexpr std::chrono::milliseconds kDrainTime{2000};        // reading what follows a last answer, so the client gets it
constexpr std::size_t kMaxDrainBytes = 8u << 20;
constexpr int kKeepAliveRequests = 20;               // then the connection is closed

struct HttpResponse {
    int status = 200;
    std::string content_type;
    std::string body;
    std::vector<std::pair<std::string, std::string>> headers;  // besides the server's own
    bool close = false;  // close the connection after it (a refused request)
};

struct HttpApp {
    // Answers a parsed request (any exception is a 500 "internal error").
    std::function<HttpResponse(const HttpRequest&)> handle;
    // The answer to a request that could not be parsed (or a 500).
    std::function<HttpResponse(int status, const char* message)> refuse;
    // "Name: value\r\n" lines sent with every response.
    std::string common_headers;
};

// A socket listening on 127.0.0.1:port (0: any free port), with `bound` the
// port; -1 and a one-line `error` (naming the port) when it cannot listen,
// e.g. because another server has it.
int listen_loopback(int port, int& bound, std::string& error);

// Serves the connections of `listen_fd` until the process ends; returns 1
// (with a line on stderr) only when it cannot start.
int serve_connections(int listen_fd, const HttpApp& app);

} // namespace prast::stepper
