// Python calls whose work runs on a thread of its own, so that Ctrl-C reaches the caller at
// once (python/module.cpp: Scene.render and Context.load).
#pragma once

#include <pybind11/pybind11.h>

#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <utility>
#include <vector>

#include "common/stop_signals.h"

namespace mcrt {

// Work that runs on a thread of its own while the calling thread, which holds the GIL between
// waits, checks for signals every 50 ms and calls the progress callback: Ctrl-C then raises
// KeyboardInterrupt within a second wherever the work is, a kernel build (which no OpenCL call
// can cut short) included. On a Python exception the work is asked to stop (`interrupted`, the
// render's stop flag) and left to end in the background: its thread holds what it uses, a
// render the context's lock, so the context's next call waits for it; a program it built is
// kept (cl/program.h, cached_program). Interpreter exit waits for such work (join_background,
// which python/mcrt/__init__.py registers with atexit).
struct Job {
    // Set by the calling thread, read by the work's: the render's RenderControl::interrupted.
    StopFlag interrupted{0};
    std::mutex mutex;
    std::condition_variable changed;
    bool done = false;                                    // under mutex
    std::exception_ptr error;                             // what the work threw; set before done
    std::vector<std::pair<uint32_t, uint32_t>> progress;  // under mutex: not yet told

    // The render's ProgressSink: queues (done, total) for the calling thread.
    void report(uint32_t done_spp, uint32_t total) {
        std::lock_guard<std::mutex> lock(mutex);
        progress.emplace_back(done_spp, total);
        changed.notify_all();
    }
};

// Runs `work` on a thread of its own and waits for it as the comment of Job says, calling
// `progress(done, total)` (if not None) for what the work reported. Rethrows what the work
// threw, or the Python exception (KeyboardInterrupt, the callback's) at once, the work told to
// stop and left to end in the background. Called with the GIL held.
void run_interruptible(const std::function<void(Job&)>& work, const pybind11::object& progress);

// Joins the background threads that have ended; with `all`, waits for the others too (checking
// for signals: a second Ctrl-C gives up the wait and is raised). Called with the GIL held.
void join_background(bool all);

// How many interrupted works are still running.
size_t background_running();

}  // namespace mcrt
