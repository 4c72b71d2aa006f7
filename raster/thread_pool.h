// A pool of worker threads that lives as long as the renderer: each stage hands
// it N tasks and waits. The calling thread works too, so threads = 1 runs
// everything on the caller with no synchronisation cost.
//
// Failures stay on the caller's side: a pool that cannot start all its threads
// (a process limit, no memory for a stack) runs with those it got and says so
// in started_fewer(), and under an address-space limit (ulimit -v) it starts
// no more than fit in half of what is left, since every thread reserves a
// whole stack and the render needs the rest; an exception thrown by a task (std::bad_alloc, ...)
// stops the run's remaining tasks and is rethrown by run() on the calling
// thread once every worker is back, so nothing calls std::terminate.
#pragma once

#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
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
    int requested() const { return requested_; }
    // "" when all requested threads run; else why fewer do, e.g. "could start
    // only 37 of 1024 threads (Resource temporarily unavailable)" or "could
    // start only 511 of 1000 threads (their 8 MiB stacks would take more than
    // half of the 8165 MiB of address space left under ulimit -v)".
    const std::string& started_fewer() const { return started_fewer_; }

    // Runs fn(task, worker) for task in [0, count); worker in [0, size()).
    // Tasks are taken in increasing order by whichever thread is free, so fn
    // must not depend on which worker runs it (results are written per task).
    // The first exception a task throws is rethrown here after the run.
    void run(int count, const std::function<void(int task, int worker)>& fn);

    static int hardware_threads();

    // What the threads spent inside runs since reset_usage(), summed over
    // threads: CPU time (the thread's own clock: time the machine gave to
    // other processes is not counted) and wall time from a thread's start on
    // a run to its finding no task left. Against the wall time of the runs,
    // busy_ms says how long threads waited for one another or for a wake-up;
    // cpu_ms against the same work on one thread, what the threads cost each
    // other (shared memory bandwidth and caches). Read between runs.
    struct Usage {
        double cpu_ms = 0, busy_ms = 0;
    };
    Usage usage() const;
    void reset_usage();

private:
    void worker_loop(int worker);
    void work(int worker);
    void work_measured(int worker);
    void shut_down();

    std::vector<std::thread> workers_;
    int requested_ = 1;
    std::string started_fewer_;
    std::mutex mutex_;
    std::condition_variable start_cv_, done_cv_;
    const std::function<void(int, int)>* fn_ = nullptr;
    int count_ = 0;
    std::atomic<int> next_{0};
    int busy_ = 0;              // workers still inside the current run
    unsigned generation_ = 0;   // bumps once per run
    bool stop_ = false;
    std::exception_ptr error_;  // first task failure of the current run
    std::vector<Usage> usage_;  // by worker, each written by its own thread
};

} // namespace prast
