// Persistent worker threads; see thread_pool.h.
#include "raster/thread_pool.h"

namespace prast {

ThreadPool::ThreadPool(int threads) {
    if (threads < 1) threads = 1;
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { worker_loop(i); });
}

ThreadPool::~ThreadPool() {
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

void ThreadPool::work(int worker) {
    for (;;) {
        int task = next_.fetch_add(1, std::memory_order_relaxed);
        if (task >= count_) return;
        (*fn_)(task, worker);
    }
}

void ThreadPool::run(int count, const std::function<void(int, int)>& fn) {
    if (count <= 0) return;
    if (workers_.empty() || count == 1) {
        for (int t = 0; t < count; ++t) fn(t, 0);
        return;
    }
    {
        std::lock_guard<std::mutex> lock(mutex_);
        fn_ = &fn;
        count_ = count;
        next_.store(0, std::memory_order_relaxed);
        busy_ = int(workers_.size());
        ++generation_;
    }
    start_cv_.notify_all();
    work(0);
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [this] { return busy_ == 0; });
    fn_ = nullptr;
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
        work(worker);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (--busy_ == 0) done_cv_.notify_one();
        }
    }
}

} // namespace prast
