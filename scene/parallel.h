// Running a few independent tasks on short-lived std::threads, for the scene
// layer's own work before a renderer (and its ThreadPool) exists: the PNG
// encoder's bands, the built-in scene's images. Internal, not installed.
#pragma once

#include <functional>

namespace prast {

// Runs fn(task) for task in [0, count) on up to `threads` threads, this one
// included, each taking the next task not yet taken, so fn must not depend
// on which thread runs it. A thread that cannot be started (a process limit,
// no memory for its stack) leaves its tasks to the others. The first task
// to throw stops the tasks not yet taken; its exception is rethrown here
// once every thread is back.
void run_on_threads(int threads, int count, const std::function<void(int)>& fn);

} // namespace prast
