#include "interruptible.h"

#include <chrono>
#include <memory>
#include <thread>

namespace py = pybind11;

namespace mcrt {
namespace {

// Threads of interrupted work, joined once they end (at the next job, or at exit). Never
// destroyed: a thread still running when the process ends is not joined by a destructor.
struct Background {
    std::mutex mutex;
    std::vector<std::pair<std::shared_ptr<Job>, std::thread>> threads;
};
Background& background() {
    static Background* b = new Background;
    return *b;
}

}  // namespace

void join_background(bool all) {
    Background& b = background();
    for (int waits = 0;; ++waits) {
        std::vector<std::pair<std::shared_ptr<Job>, std::thread>> ended;
        bool running = false;
        {
            std::lock_guard<std::mutex> lock(b.mutex);
            for (auto it = b.threads.begin(); it != b.threads.end();) {
                std::lock_guard<std::mutex> job_lock(it->first->mutex);
                if (it->first->done) {
                    ended.push_back(std::move(*it));
                    it = b.threads.erase(it);
                } else {
                    running = true;
                    ++it;
                }
            }
        }
        for (auto& t : ended) t.second.join();  // it has ended: returns at once
        if (!all || !running) return;
        if (waits == 20)  // a drain ends sooner: this is a kernel build or a load
            PySys_WriteStderr(
                "mcrt: waiting for an interrupted kernel build or load to end (Ctrl-C again: "
                "quit without waiting)\n");
        {
            py::gil_scoped_release release;
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
}

void run_interruptible(const std::function<void(Job&)>& work, const py::object& progress) {
    join_background(false);
    auto job = std::make_shared<Job>();
    std::thread thread([job, work] {
        std::exception_ptr error;
        try {
            work(*job);
        } catch (...) {
            error = std::current_exception();
        }
        std::lock_guard<std::mutex> lock(job->mutex);
        job->error = error;
        job->done = true;
        job->changed.notify_all();
    });
    for (;;) {
        std::vector<std::pair<uint32_t, uint32_t>> told;
        bool done = false;
        {
            py::gil_scoped_release release;
            std::unique_lock<std::mutex> lock(job->mutex);
            job->changed.wait_for(lock, std::chrono::milliseconds(50),
                                  [&] { return job->done || !job->progress.empty(); });
            told.swap(job->progress);
            done = job->done;
        }
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (!progress.is_none())
                for (const auto& p : told) progress(p.first, p.second);
        } catch (py::error_already_set&) {
            job->interrupted = 1;
            if (done) {
                thread.join();
            } else {
                std::lock_guard<std::mutex> lock(background().mutex);
                background().threads.emplace_back(job, std::move(thread));
            }
            throw;
        }
        if (done) break;
    }
    thread.join();
    if (job->error) std::rethrow_exception(job->error);
}

size_t background_running() {
    size_t running = 0;
    std::lock_guard<std::mutex> lock(background().mutex);
    for (const auto& t : background().threads) {
        std::lock_guard<std::mutex> job_lock(t.first->mutex);
        running += t.first->done ? 0 : 1;
    }
    return running;
}

}  // namespace mcrt
