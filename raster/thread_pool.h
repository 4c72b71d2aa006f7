// A pool of worker threads that lives as long as the renderer: each stage hands
// it N tasks and waits. The calling thread works too, so threads = 1 runs
// everything on the caller with no synchronisation cost.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace prast {

class ThreadPool {
public:
    explicit ThreadPool(int threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    int size() const { return int(workers_.size()) + 1; }

    // Runs fn(task, worker) for task in [0, count); worker in [0, size()).
    // Tasks are taken in increasing order by whichever thread is free, so fn
    // must not depend on which worker runs it (results are written per task).
    void run(int count, const std::function<void(int task, int worker)>& fn);

    static int hardware_threads();

private:
    void worker_loop(int worker);
    void work(int worker);

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable start_cv_, done_cv_;
    const std::function<void(int, int)>* fn_ = nullptr;
    int count_ = 0;
    std::atomic<int> next_{0};
    int busy_ = 0;              // workers still inside the current run
    unsigned generation_ = 0;   // bumps once per run
    bool stop_ = false;
};

} // namespace prast
