// After every output is complete a stop signal has nothing left to save: SIGINT and SIGTERM are
// ignored from then on, so the process still exits 0 (ROBUSTNESS.md "Signals and pipes").
#pragma once

#include <csignal>

namespace mcrt {

// The flag a stop signal raises while a render runs (the render's interrupt guard sets it), or
// nullptr: work that blocks outside the render loop (the output commit's wait for another
// process's lock) reads it through stop_requested().
void set_stop_flag(const volatile std::sig_atomic_t* flag);
bool stop_requested();

// Ignores SIGINT and SIGTERM for the rest of the process.
void outputs_complete();

// True once outputs_complete() ran: the render's interrupt guard must not restore the default
// (terminating) actions then.
bool outputs_are_complete();

// SIGPIPE ignored (a closed stderr pipe makes writes fail, harmlessly, instead of killing the
// process before the image is written); SIGXFSZ too, so a file-size limit is a write error.
void ignore_pipe_signals();

}  // namespace mcrt
