#include "cli/cli.h"
#include "common/stop_signals.h"
#include "common/test_hooks.h"

int main(int argc, char** argv) {
    mcrt::ignore_pipe_signals();
    const int status = mcrt::run_cli(argc, argv);
    mcrt::test_pause("exit");
    return status;
}
