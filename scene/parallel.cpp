// See parallel.h.
#include "scene/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace prast {

void run_on_threads(int threads, int count, const std::function<void(int)>& fn) {
    std::atomic<int> next{0};
    std::mutex failed_lock;
    std::exception_ptr failed;
    auto work = [&] {
        try {
            for (int b = next++; b < count; b = next++) fn(b);
        } catch (...) {
            next = count;  // the others stop too
            const std::lock_guard<std::mutex> lock(failed_lock);
            if (!failed) failed = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    // Unwinding past joinable threads would terminate the process, so a
    // failure to start one (or to grow the vector) only ends the starting.
    try {
        pool.reserve(std::size_t(std::max(0, std::min(threads, count))));
        for (int t = 1; t < std::min(threads, count); ++t) pool.emplace_back(work);
    } catch (...) {
    }
    work();
    for (std::thread& t : pool) t.join();
    if (failed) std::rethrow_exception(failed);
}

} // namespace prast
