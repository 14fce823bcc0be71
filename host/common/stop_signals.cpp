#include "common/stop_signals.h"

#include <csignal>

namespace mcrt {

namespace {
volatile std::sig_atomic_t g_outputs_complete = 0;
}

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
