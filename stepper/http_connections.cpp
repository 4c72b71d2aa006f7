// The event thread and the workers; see http_connections.h.
//
// The event thread owns every connection that is not being answered: it
// reads request heads, closes connections past their deadlines and closes
// every socket (so a descriptor a worker holds is never reused under it). A
// complete head (or a refused one) goes to the workers as a job, with the
// socket out of the event set; the worker makes the answer, writes what the
// socket takes at once and hands the connection back, to be kept alive,
// drained or closed, or with the rest of its answer for the event thread to
// write as the client reads: a client that stops reading never holds a
// worker. Answers waiting so are capped in bytes (kMaxPendingBytes); past
// the cap the connection whose client has read nothing for longest is
// closed.
#include "stepper/http_connections.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>

#include <malloc.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

namespace prast::stepper {

namespace {

using Clock = std::chrono::steady_clock;

// Descriptors kept free for the listening socket, epoll, the wake-up
// eventfd, the standard streams and whatever a library opens.
constexpr std::size_t kReservedFds = 32;
constexpr std::chrono::milliseconds kTick{100};  // how often deadlines are checked
constexpr int kAcceptsPerWakeup = 64;            // then other sockets get their turn
// Bytes of answers after which, once the workers are idle, freed memory is
// given back to the system (the workers' malloc arenas keep it otherwise).
constexpr std::size_t kTrimAfterBytes = 1u << 20;
// The kernel's send buffer of a connection (it doubles the number), fixed
// rather than grown up to 4 MiB: an answer a client does not read waits in
// the server's count (kMaxPendingBytes), not in kernel memory by the GiB.
constexpr int kSendBufferBytes = 256 << 10;

// What a connection does after its answer: `write` is the rest of it, then `then`.
enum class After { keep, drain, close, write };

struct Connection {
    enum class State { idle, reading, busy, writing, draining };
    int fd = -1;
    State state = State::idle;
    std::string in;  // bytes read and not yet part of an answered request
    HeadScanner scanner;
    Clock::time_point since;  // idle: since the last answer; reading: the head's first byte; draining: start
    Clock::time_point last;   // the last byte read
    int served = 0;
    std::size_t drained = 0;
    std::string out;  // writing: the answer, of which out_done bytes are sent, then `then`
    std::size_t out_done = 0;
    After then = After::keep;
    std::size_t held = 0;  // the memory of `out`, counted in the server's pending bytes
    std::uint64_t order = 0;  // accept order: at the cap the oldest goes first
};

struct Job {
    Connection* conn;
    bool parsed;
    HttpRequest request;  // when parsed
    int status;           // when not: the refusal
    const char* message;
};


bool contains_token_close(const std::string& value) {
    std::string v = value;
    for (char& c : v) c = char(std::tolower(static_cast<unsigned char>(c)));
    return v.find("close") != std::string::npos;
}

// Sends what the socket takes now; false on an error (the client is gone).
bool send_some(int fd, const std::string& data, std::size_t& done) {
    while (done < data.size()) {
        const ssize_t n = ::send(fd, data.data() + done, data.size() - done, MSG_NOSIGNAL);
        if (n > 0) {
            done += std::size_t(n);
        } else if (n < 0 && errno == EINTR) {
            continue;
        } else {
            return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
        }
    }
    return true;
}

class Server {
public:
    Server(int listen_fd, const HttpApp& app) : listen_fd_(listen_fd), app_(app) {}
    int run();

private:
    void worker();
    std::pair<After, After> answer(Job& job);
    void accept_ready(Clock::time_point now);
    void on_event(int fd, Clock::time_point now);
    void on_writable(Connection* c, Clock::time_point now);
    void answered(Connection* c, After then, Clock::time_point now);
    void limit_pending();
    void take_returned(Clock::time_point now);
    void process(Connection* c, Clock::time_point now);
    void dispatch(Connection* c, Job job);
    void sweep(Clock::time_point now);
    bool evict_one();
    void close_conn(Connection* c);
    void abort_conn(Connection* c);
    void watch(Connection* c, int op, std::uint32_t events = EPOLLIN | EPOLLRDHUP);
    void set_listening(bool on);

    int listen_fd_, epoll_fd_ = -1, wake_fd_ = -1;
    const HttpApp& app_;
    std::size_t cap_ = kMaxConnections, count_ = 0;
    std::size_t pending_ = 0;  // memory of the answers the event thread still has to write
    std::size_t in_workers_ = 0;  // jobs given and not yet returned
    std::atomic<std::size_t> answered_bytes_{0};  // since the last trim
    std::uint64_t next_order_ = 0;
    bool listening_ = false;
    std::vector<std::unique_ptr<Connection>> by_fd_;  // the event thread's only

    std::mutex mutex_;  // guards jobs_ and returned_
    std::condition_variable job_ready_;
    std::deque<Job> jobs_;
    struct Returned {
        Connection* conn;
        After after, then;
    };
    std::vector<Returned> returned_;
};

// The descriptor limit: raised to what the connection cap needs (when the
// hard limit allows), and the cap lowered to what it allows.
std::size_t connection_cap() {
    rlimit lim{};
    if (::getrlimit(RLIMIT_NOFILE, &lim) != 0) return 64;
    const rlim_t want = kMaxConnections + kReservedFds;
    if (lim.rlim_cur != RLIM_INFINITY && lim.rlim_cur < want) {
        rlimit raised = lim;
        raised.rlim_cur = lim.rlim_max == RLIM_INFINITY ? want : std::min(want, lim.rlim_max);
        if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) lim = raised;
    }
    if (lim.rlim_cur == RLIM_INFINITY || lim.rlim_cur >= want) return kMaxConnections;
    return lim.rlim_cur > kReservedFds + 8 ? std::size_t(lim.rlim_cur - kReservedFds) : 8;
}

int Server::run() {
    cap_ = connection_cap();
    epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
    wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (epoll_fd_ < 0 || wake_fd_ < 0) {
        std::fprintf(stderr, "step: cannot serve: %s\n", std::strerror(errno));
        return 1;
    }
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = wake_fd_;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, wake_fd_, &ev);
    ev.data.fd = listen_fd_;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, listen_fd_, &ev);
    listening_ = true;

    // Workers: as many as can start (a process limit may stop some).
    std::vector<std::thread> workers;
    for (std::size_t i = 0; i < kHttpWorkers; ++i) {
        try {
            workers.emplace_back([this] { worker(); });
        } catch (const std::system_error&) {
            break;
        }
    }
    if (workers.empty()) {
        std::fprintf(stderr, "step: cannot serve: no worker thread could start\n");
        return 1;
    }

    epoll_event events[64];
    Clock::time_point last_sweep = Clock::now();
    for (;;) {
        const int n = ::epoll_wait(epoll_fd_, events, 64, int(kTick.count()));
        const Clock::time_point now = Clock::now();
        for (int i = 0; i < n; ++i) {
            const int fd = events[i].data.fd;
            if (fd == listen_fd_) accept_ready(now);
            else if (fd == wake_fd_) take_returned(now);
            else on_event(fd, now);
        }
        if (now - last_sweep >= kTick) {
            sweep(now);
            last_sweep = now;
        }
    }
}

void Server::set_listening(bool on) {
    if (on == listening_) return;
    epoll_event ev{};
    ev.events = on ? std::uint32_t(EPOLLIN) : 0u;
    ev.data.fd = listen_fd_;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_MOD, listen_fd_, &ev);
    listening_ = on;
}

void Server::watch(Connection* c, int op, std::uint32_t events) {
    epoll_event ev{};
    ev.events = events;
    ev.data.fd = c->fd;
    ::epoll_ctl(epoll_fd_, op, c->fd, &ev);
}

void Server::close_conn(Connection* c) {
    const int fd = c->fd;
    pending_ -= c->held;
    ::close(fd);  // also leaves the epoll set
    by_fd_[std::size_t(fd)].reset();
    --count_;
    if (count_ < cap_) set_listening(true);
}

// Closes with a reset: the kernel drops the unsent answer at once instead
// of keeping it (and the socket) for a client that does not read.
void Server::abort_conn(Connection* c) {
    const linger now{1, 0};
    ::setsockopt(c->fd, SOL_SOCKET, SO_LINGER, &now, sizeof now);
    close_conn(c);
}

// Makes room for a new connection: closes the oldest one that is idle (or
// draining), else the oldest still sending its head, else the oldest whose
// answer waits for its client to read; never one a worker has.
bool Server::evict_one() {
    Connection* oldest_idle = nullptr;
    Connection* oldest_reading = nullptr;
    Connection* oldest_writing = nullptr;
    for (const auto& p : by_fd_) {
        Connection* c = p.get();
        if (!c || c->state == Connection::State::busy) continue;
        Connection*& slot = c->state == Connection::State::reading   ? oldest_reading
                            : c->state == Connection::State::writing ? oldest_writing
                                                                     : oldest_idle;
        if (!slot || c->order < slot->order) slot = c;
    }
    Connection* victim = oldest_idle ? oldest_idle : oldest_reading ? oldest_reading : oldest_writing;
    if (!victim) return false;
    if (victim->state == Connection::State::writing) abort_conn(victim);
    else close_conn(victim);
    return true;
}

void Server::accept_ready(Clock::time_point now) {
    for (int i = 0; i < kAcceptsPerWakeup; ++i) {
        const bool full = count_ >= cap_;
        if (full && !evict_one()) {
            set_listening(false);  // every connection is being answered; the backlog waits
            return;
        }
        const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) {
            if (errno == EINTR || errno == ECONNABORTED) continue;
            if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
                // Out of descriptors (or memory) below the cap: free one, or
                // stop accepting until a connection closes or the next tick.
                if (evict_one()) continue;
                set_listening(false);
            }
            return;  // EAGAIN: none waiting
        }
        const int one = 1, send_buffer = kSendBufferBytes;
        ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &send_buffer, sizeof send_buffer);
        if (by_fd_.size() <= std::size_t(fd)) by_fd_.resize(std::size_t(fd) + 1);
        auto c = std::make_unique<Connection>();
        c->fd = fd;
        c->since = c->last = now;
        c->order = next_order_++;
        Connection* raw = c.get();
        by_fd_[std::size_t(fd)] = std::move(c);
        ++count_;
        watch(raw, EPOLL_CTL_ADD);
        // At the cap, one a wakeup: the listening socket is readable again if
        // more wait, and none is closed for a connection that is not there.
        if (full) return;
    }
}

void Server::on_event(int fd, Clock::time_point now) {
    if (fd < 0 || std::size_t(fd) >= by_fd_.size() || !by_fd_[std::size_t(fd)]) return;
    Connection* c = by_fd_[std::size_t(fd)].get();
    if (c->state == Connection::State::busy) return;  // a stale event
    if (c->state == Connection::State::writing) return on_writable(c, now);
    char buf[kMaxHeadBytes + 1];
    if (c->state == Connection::State::draining) {
        const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return;
        if (n <= 0 || (c->drained += std::size_t(n)) > kMaxDrainBytes) close_conn(c);
        return;
    }
    // Never more than the head limit needs: the scanner refuses one byte past it.
    const std::size_t want = c->in.size() < sizeof buf ? sizeof buf - c->in.size() : 1;
    const ssize_t n = ::recv(fd, buf, want, 0);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return;
    if (n <= 0) {  // the client closed (a half-sent request gets no answer), or an error
        close_conn(c);
        return;
    }
    if (c->state == Connection::State::idle) {
        c->state = Connection::State::reading;
        c->since = now;
    }
    c->last = now;
    c->in.append(buf, std::size_t(n));
    process(c, now);
}

// A head complete in `in`, or refused: a job for the workers.
void Server::process(Connection* c, Clock::time_point) {
    const HeadScanner::State st = c->scanner.feed(c->in);
    if (st == HeadScanner::State::more) return;
    Job job{c, false, {}, 0, nullptr};
    if (st == HeadScanner::State::error) {
        job.status = c->scanner.error_status();
        job.message = c->scanner.error_message();
        c->in.clear();
    } else {
        const std::size_t head = c->scanner.head_bytes();
        const char* message = nullptr;
        job.parsed = parse_request_head(std::string_view(c->in).substr(0, head), job.request, message);
        if (!job.parsed) {
            job.status = 400;
            job.message = message;
        }
        c->in.erase(0, head);
        if (c->in.empty()) std::string().swap(c->in);  // an idle connection holds no buffer
    }
    c->scanner.reset();
    dispatch(c, std::move(job));
}

void Server::dispatch(Connection* c, Job job) {
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, c->fd, nullptr);
    c->state = Connection::State::busy;
    ++in_workers_;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        jobs_.push_back(std::move(job));
    }
    job_ready_.notify_one();
}

void Server::take_returned(Clock::time_point now) {
    std::uint64_t wakes = 0;
    while (::read(wake_fd_, &wakes, sizeof wakes) > 0) {
    }
    std::vector<Returned> back;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        back.swap(returned_);
    }
    in_workers_ -= back.size();
    for (const Returned& r : back) {
        Connection* c = r.conn;
        c->since = c->last = now;
        if (r.after == After::close) {
            close_conn(c);
        } else if (r.after == After::write) {
            c->state = Connection::State::writing;
            c->held = c->out.capacity();  // the whole string stays until it is all sent
            pending_ += c->held;
            c->then = r.then;
            watch(c, EPOLL_CTL_ADD, EPOLLOUT);
        } else {
            answered(c, r.after, now);
        }
    }
    limit_pending();
}

// The answer is all written: keep the connection for the next request, or
// drain it (the last answer: a FIN, then what the client still sends is read
// for a moment, so that closing does not reset the connection and destroy
// the answer before the client has read it).
void Server::answered(Connection* c, After then, Clock::time_point now) {
    c->since = c->last = now;
    std::string().swap(c->out);
    c->out_done = 0;
    pending_ -= c->held;
    c->held = 0;
    if (then == After::drain) {
        ::shutdown(c->fd, SHUT_WR);
        c->state = Connection::State::draining;
        std::string().swap(c->in);
        watch(c, EPOLL_CTL_ADD);
        return;
    }
    watch(c, EPOLL_CTL_ADD);
    c->state = c->in.empty() ? Connection::State::idle : Connection::State::reading;
    if (!c->in.empty()) process(c, now);  // a pipelined request already read
}

void Server::on_writable(Connection* c, Clock::time_point now) {
    const std::size_t before = c->out_done;
    if (!send_some(c->fd, c->out, c->out_done)) {
        close_conn(c);
        return;
    }
    if (c->out_done > before) c->last = now;
    if (c->out_done < c->out.size()) return;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, c->fd, nullptr);
    answered(c, c->then, now);
}

// Answers waiting for their clients hold at most kMaxPendingBytes: past it,
// the connection whose client has gone longest without reading is closed.
void Server::limit_pending() {
    while (pending_ > kMaxPendingBytes) {
        Connection* slowest = nullptr;
        for (const auto& p : by_fd_) {
            Connection* c = p.get();
            if (c && c->state == Connection::State::writing && (!slowest || c->last < slowest->last)) slowest = c;
        }
        if (!slowest) return;
        abort_conn(slowest);
    }
}

void Server::sweep(Clock::time_point now) {
    for (std::size_t fd = 0; fd < by_fd_.size(); ++fd) {
        Connection* c = by_fd_[fd].get();
        if (!c) continue;
        bool expired = false;
        switch (c->state) {
        case Connection::State::idle: expired = now - c->since >= kKeepAliveIdle; break;
        case Connection::State::reading:
            expired = now - c->since >= kRequestDeadline || now - c->last >= kReadIdle;
            break;
        case Connection::State::draining: expired = now - c->since >= kDrainTime; break;
        case Connection::State::writing:
            if (now - c->last >= kWriteIdle || now - c->since >= kWriteDeadline) {
                abort_conn(c);
                continue;
            }
            break;
        case Connection::State::busy: break;
        }
        if (expired) close_conn(c);  // a stalled request gets no answer
    }
    if (count_ < cap_) set_listening(true);  // after a shortage of descriptors, try again
    if (in_workers_ == 0 && pending_ == 0 && answered_bytes_ > kTrimAfterBytes) {
        answered_bytes_ = 0;
        ::malloc_trim(0);
    }
}

void Server::worker() {
    for (;;) {
        Job job{};
        {
            std::unique_lock<std::mutex> lock(mutex_);
            job_ready_.wait(lock, [this] { return !jobs_.empty(); });
            job = std::move(jobs_.front());
            jobs_.pop_front();
        }
        std::pair<After, After> after{After::close, After::close};
        try {
            after = answer(job);
        } catch (...) {  // no memory for the answer's bytes: the connection is closed
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            returned_.push_back({job.conn, after.first, after.second});
        }
        const std::uint64_t one = 1;
        while (::write(wake_fd_, &one, sizeof one) < 0 && errno == EINTR) {
        }
    }
}

// Makes the answer and writes what the socket takes now; what the
// connection does next (with `write`: the rest is in `out`, then `second`).
std::pair<After, After> Server::answer(Job& job) {
    Connection* c = job.conn;
    HttpResponse res;
    try {
        res = job.parsed ? app_.handle(job.request) : app_.refuse(job.status, job.message);
    } catch (...) {
        res = app_.refuse(500, "internal error");
    }
    if (!job.parsed) res.close = true;
    ++c->served;
    const bool keep = !res.close && !job.request.http10 && !contains_token_close(job.request.header("connection")) &&
                      c->served < kKeepAliveRequests;
    std::string out = status_line(res.status);
    if (!res.content_type.empty()) out += "Content-Type: " + res.content_type + "\r\n";
    out += "Content-Length: " + std::to_string(res.body.size()) + "\r\n";
    for (const auto& [name, value] : res.headers) out += name + ": " + value + "\r\n";
    out += app_.common_headers;
    if (!keep) out += "Connection: close\r\n";
    out += "\r\n";
    if (!(job.parsed && job.request.method == "HEAD")) out += res.body;
    answered_bytes_ += out.size();
    const After then = keep ? After::keep : After::drain;
    std::size_t done = 0;
    if (!send_some(c->fd, out, done)) return {After::close, After::close};
    if (done == out.size()) return {then, then};
    c->out = std::move(out);
    c->out_done = done;
    return {After::write, then};
}

} // namespace

int listen_loopback(int port, int& bound, std::string& error) {
    const std::string where = "127.0.0.1:" + std::to_string(port);
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        error = "cannot listen on " + where + ": " + std::strerror(errno);
        return -1;
    }
    // SO_REUSEADDR only lets a restarted server bind past TIME_WAIT; Linux
    // still refuses a second listener. No SO_REUSEPORT: that would let two
    // servers share the port and split the requests between them.
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(std::uint16_t(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, kListenBacklog) != 0) {
        const int e = errno;
        ::close(fd);
        error = e == EADDRINUSE ? "cannot listen on " + where + ": the port is in use (another server? try --port 0)"
                                : "cannot listen on " + where + ": " + std::strerror(e);
        return -1;
    }
    socklen_t len = sizeof addr;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    bound = ntohs(addr.sin_port);
    return fd;
}

int serve_connections(int listen_fd, const HttpApp& app) {
    Server server(listen_fd, app);
    return server.run();
}

} // namespace prast::stepper
