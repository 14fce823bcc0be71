// The signals that ask a render to stop, and what becomes of them once its outputs are complete
// (ROBUSTNESS.md "Signals and pipes").
#pragma once

#include <atomic>
#include <csignal>

namespace mcrt {

// SIGINT (Ctrl-C), SIGTERM (kill, a batch system's end of a job) and SIGHUP (a closed terminal or
// ssh session): each stops a render, which writes the samples done so far.
inline constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

// A flag that a signal handler raises and other threads read (the render loop, the device
// threads, a kernel build's wait): a lock-free atomic, which a handler may write (C++17
// [support.signal]) and threads may read without a data race, as a volatile sig_atomic_t may not.
using StopFlag = std::atomic<int>;
static_assert(StopFlag::is_always_lock_free, "a stop flag must be writable from a signal handler");

// The flag a stop signal raises while a render runs (the render's interrupt guard sets it), or
// nullptr: work that blocks outside the render loop (the output commit's wait for another
// process's lock) reads it through stop_requested().
void set_stop_flag(const StopFlag* flag);
bool stop_requested();

// After every output is complete a stop signal has nothing left to save: the stop signals are
// ignored for the rest of the process, so it still exits 0.
void outputs_complete();

// True once outputs_complete() ran: the render's interrupt guard must not restore the default
// (terminating) actions then.
bool outputs_are_complete();

// True when `sig` was ignored when the process started (SIGHUP under nohup), read before any
// library could install a handler over it (LLVM, inside an OpenCL compiler, catches SIGHUP, SIGINT
// and SIGTERM, and would hide that they were ignored).
bool ignored_at_start(int sig);

// SIGPIPE ignored (a closed stderr pipe makes writes fail, harmlessly, instead of killing the
// process before the image is written); SIGXFSZ too, so a file-size limit is a write error.
void ignore_pipe_signals();

}  // namespace mcrt
