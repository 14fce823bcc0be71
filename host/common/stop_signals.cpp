#include "common/stop_signals.h"

#include <csignal>

namespace mcrt {

namespace {
volatile std::sig_atomic_t g_outputs_complete = 0;
const volatile std::sig_atomic_t* g_stop_flag = nullptr;
}  // namespace

void set_stop_flag(const volatile std::sig_atomic_t* flag) { g_stop_flag = flag; }

bool stop_requested() { return g_stop_flag != nullptr && *g_stop_flag != 0; }

void outputs_complete() {
    g_outputs_complete = 1;
    std::signal(SIGINT, SIG_IGN);
    std::signal(SIGTERM, SIG_IGN);
}

bool outputs_are_complete() { return g_outputs_complete != 0; }

void ignore_pipe_signals() {
    std::signal(SIGPIPE, SIG_IGN);
    std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace mcrt
