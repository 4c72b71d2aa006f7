// Persistent worker threads; see thread_pool.h.
#include "raster/thread_pool.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <system_error>

#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

namespace prast {

namespace {

double thread_cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// Adds the calling thread's CPU and wall time from construction to
// destruction to `u` (also when a task throws through it).
class UsageTimer {
public:
    explicit UsageTimer(ThreadPool::Usage& u) : u_(u), t0_(Clock::now()), c0_(thread_cpu_ms()) {}
    ~UsageTimer() {
        u_.cpu_ms += thread_cpu_ms() - c0_;
        u_.busy_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0_).count();
    }
    UsageTimer(const UsageTimer&) = delete;
    UsageTimer& operator=(const UsageTimer&) = delete;

private:
    using Clock = std::chrono::steady_clock;
    ThreadPool::Usage& u_;
    Clock::time_point t0_;
    double c0_;
};

std::string mib(std::uint64_t bytes) { return std::to_string((bytes + (std::uint64_t(1) << 19)) >> 20) + " MiB"; }

// The address space a new thread takes: its stack and guard as the default
// thread attributes give them (std::thread uses those).
std::uint64_t thread_reservation() {
    pthread_attr_t attr;
    std::size_t stack = 0, guard = 0;
    if (pthread_getattr_default_np(&attr) == 0) {
        pthread_attr_getstacksize(&attr, &stack);
        pthread_attr_getguardsize(&attr, &guard);
        pthread_attr_destroy(&attr);
    }
    return stack == 0 ? std::uint64_t(8) << 20 : std::uint64_t(stack) + std::uint64_t(guard);
}

// The address space the process has mapped (/proc/self/statm), 0 when unknown.
std::uint64_t mapped_bytes() {
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (!f) return 0;
    unsigned long long pages = 0;
    const int got = std::fscanf(f, "%llu", &pages);
    std::fclose(f);
    const long page = sysconf(_SC_PAGE_SIZE);
    return got == 1 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : 0;
}

// Under an address-space limit (ulimit -v), how many more threads may start
// so that their stacks take at most half of what is left: each reserves its
// whole stack (8 MiB by default) whether it uses it or not, so a thousand
// threads would leave the render itself nothing. "" in `why` when all may.
int threads_that_fit(int wanted, std::string& why) {
    rlimit limit{};
    if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return wanted;
    const std::uint64_t cap = std::uint64_t(limit.rlim_cur), used = mapped_bytes();
    const std::uint64_t room = cap > used ? (cap - used) / 2 : 0;
    const std::uint64_t each = thread_reservation();
    if (std::uint64_t(wanted) * each <= room) return wanted;
    why = "their " + mib(each) + " stacks would take more than half of the " + mib(cap > used ? cap - used : 0) +
          " of address space left under ulimit -v";
    return int(room / each);
}

} // namespace

ThreadPool::ThreadPool(int threads) : requested_(threads < 1 ? 1 : threads) {
    usage_.resize(std::size_t(requested_));
    std::string why;
    const int workers = threads_that_fit(requested_ - 1, why);
    if (!why.empty())
        started_fewer_ = "could start only " + std::to_string(workers + 1) + " of " + std::to_string(requested_) +
                         " threads (" + why + ")";
    workers_.reserve(std::size_t(workers));
    for (int i = 1; i <= workers; ++i) {
        try {
            workers_.emplace_back([this, i] { worker_loop(i); });
        } catch (const std::system_error& e) {
            // Keep the threads that started; the caller's thread makes one more.
            started_fewer_ = "could start only " + std::to_string(i) + " of " + std::to_string(requested_) +
                             " threads (" + e.code().message() + ")";
            break;
        } catch (const std::bad_alloc&) {
            started_fewer_ = "could start only " + std::to_string(i) + " of " + std::to_string(requested_) +
                             " threads (out of memory)";
            break;
        }
    }
}

ThreadPool::~ThreadPool() { shut_down(); }

void ThreadPool::shut_down() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
        ++generation_;
    }
    start_cv_.notify_all();
    for (std::thread& t : workers_) t.join();
}

int ThreadPool::hardware_threads() {
    unsigned n = std::thread::hardware_concurrency();
    return n == 0 ? 1 : int(n);
}

ThreadPool::Usage ThreadPool::usage() const {
    Usage u;
    for (const Usage& w : usage_) {
        u.cpu_ms += w.cpu_ms;
        u.busy_ms += w.busy_ms;
    }
    return u;
}

void ThreadPool::reset_usage() { usage_.assign(usage_.size(), Usage{}); }

void ThreadPool::work_measured(int worker) {
    UsageTimer timer(usage_[std::size_t(worker)]);
    work(worker);
}

void ThreadPool::work(int worker) {
    for (;;) {
        int task = next_.fetch_add(1, std::memory_order_relaxed);
        if (task >= count_) return;
        try {
            (*fn_)(task, worker);
        } catch (...) {
            std::lock_guard<std::mutex> lock(mutex_);
            if (!error_) error_ = std::current_exception();
            // No new task starts; those running finish.
            next_.store(count_, std::memory_order_relaxed);
            return;
        }
    }
}

void ThreadPool::run(int count, const std::function<void(int, int)>& fn) {
    if (count <= 0) return;
    if (workers_.empty() || count == 1) {
        UsageTimer timer(usage_[0]);
        for (int t = 0; t < count; ++t) fn(t, 0);
        return;
    }
    {
        std::lock_guard<std::mutex> lock(mutex_);
        fn_ = &fn;
        count_ = count;
        next_.store(0, std::memory_order_relaxed);
        busy_ = int(workers_.size());
        error_ = nullptr;
        ++generation_;
    }
    start_cv_.notify_all();
    work_measured(0);
    std::exception_ptr error;
    {
        std::unique_lock<std::mutex> lock(mutex_);
        done_cv_.wait(lock, [this] { return busy_ == 0; });
        fn_ = nullptr;
        error = error_;
        error_ = nullptr;
    }
    if (error) std::rethrow_exception(error);
}

void ThreadPool::worker_loop(int worker) {
    unsigned seen = 0;
    for (;;) {
        {
            std::unique_lock<std::mutex> lock(mutex_);
            start_cv_.wait(lock, [&] { return generation_ != seen; });
            seen = generation_;
            if (stop_) return;
        }
        work_measured(worker);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (--busy_ == 0) done_cv_.notify_one();
        }
    }
}

} // namespace prast
