// `mcrt render` (and devices, bench, integrate) in a supervised child process: the command (the
// worker) runs in a child of the same executable, and the parent (the supervisor) only waits for
// it (and passes a terminal's Ctrl-Z on to it). Kernel code that never
// returns cannot be stopped inside the process that runs it, and code that writes out of bounds
// kills that process; the supervisor outlives both. It forwards a stop signal to the worker and
// kills it when it has not stopped within a grace period, backs up the time limit the same way,
// and turns a death by a signal into one `mcrt: error:` line and exit 1 (docs/ROBUSTNESS.md
// "Kernels that hang or crash"). The worker tells it its stage over a pipe. The device listing,
// bench and integrate run under it too, since an ICD loader or driver can crash in them.
#pragma once

#include <optional>
#include <string>

namespace mcrt {

// Called first in main, before MPI is joined or OpenCL touched. For `mcrt render ...`,
// `devices`, `bench` and `integrate` (unless
// MCRT_NO_SUPERVISOR is set, or /proc/self/exe cannot be found or started) runs the command in a
// worker child and returns the status to exit with. Otherwise returns nothing and the caller
// runs the command in this process: in the worker itself (MCRT_SUPERVISED set), which is then
// set up to end with its supervisor, or in a process without one.
std::optional<int> supervise_command(int argc, char** argv);

// The worker's side: one line to the supervisor (nothing in a process without one).
//   "estimator PATH"   the estimator file the kernels run (for the messages)
//   "rank N"           this worker is rank N of an MPI job
//   "launch T BAR"     kernels run on the devices; T the time limit in seconds (0: none), BAR 1
//                      when a progress bar is drawn on stderr
//   "serve"            a rank above 0: rank 0 decides when it stops, stop signals are ignored
//   "writing"          the render is over and the outputs are being written
//   "done"             the outputs are complete: stop signals are ignored from now on
void report_to_supervisor(const std::string& line);

// Seconds a worker is given to stop after a stop signal, or after its time limit, before the
// supervisor kills it.
constexpr double kSupervisorGraceSeconds = 5.0;

}  // namespace mcrt
