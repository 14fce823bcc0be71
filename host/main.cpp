#include <cstdlib>
#include <cstring>
#include <optional>

#include "cl/build_child.h"
#include "cli/cli.h"
#include "cli/supervisor.h"
#include "common/stop_signals.h"
#include "common/test_hooks.h"
#include "mpi/job.h"

int main(int argc, char** argv) {
    // A kernel build for one device in a child process (host/cl/build_child.h), before anything
    // else: it joins no MPI job and parses no options.
    if (argc == 4 && std::strcmp(argv[1], "build-program") == 0)
        return mcrt::run_build_program_child(argv[2], std::atoi(argv[3]));
    // SIGPIPE ignored before anything else, in the supervisor too: a closed stderr pipe must
    // not kill it while it reports a worker's death.
    mcrt::ignore_pipe_signals();
    // `mcrt render` (devices, bench, integrate) runs in a supervised child of this executable
    // (host/cli/supervisor.h), started before anything else: the child joins the MPI job and
    // touches OpenCL itself.
    if (const std::optional<int> status = mcrt::supervise_command(argc, argv)) return *status;
    mcrt::JobSession job;  // joins the MPI job under mpirun or srun (host/mpi/job.h)
    const int status = mcrt::run_cli(argc, argv);
    mcrt::test_pause("exit");
    return status;
}
