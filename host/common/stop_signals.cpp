#include "common/stop_signals.h"

namespace mcrt {

namespace {
volatile std::sig_atomic_t g_outputs_complete = 0;
const StopFlag* g_stop_flag = nullptr;

// Read during static initialisation, before main and before any OpenCL library is loaded.
const bool g_hangup_ignored = [] {
    struct sigaction action {};
    return sigaction(SIGHUP, nullptr, &action) == 0 && action.sa_handler == SIG_IGN;
}();
}  // namespace

void set_stop_flag(const StopFlag* flag) { g_stop_flag = flag; }

bool stop_requested() { return g_stop_flag != nullptr && *g_stop_flag != 0; }

bool ignored_at_start(int sig) { return sig == SIGHUP && g_hangup_ignored; }

void outputs_complete() {
    g_outputs_complete = 1;
    for (int sig : kStopSignals) std::signal(sig, SIG_IGN);
}

bool outputs_are_complete() { return g_outputs_complete != 0; }

void ignore_pipe_signals() {
    std::signal(SIGPIPE, SIG_IGN);
    std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace mcrt
