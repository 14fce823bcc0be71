#include <cstdlib>
#include <cstring>

#include "cl/build_child.h"
#include "cli/cli.h"
#include "common/stop_signals.h"
#include "common/test_hooks.h"
#include "mpi/job.h"

int main(int argc, char** argv) {
    // A kernel build for one device in a child process (host/cl/build_child.h), before anything
    // else: it joins no MPI job and parses no options.
    if (argc == 4 && std::strcmp(argv[1], "build-program") == 0)
        return mcrt::run_build_program_child(argv[2], std::atoi(argv[3]));
    mcrt::ignore_pipe_signals();
    mcrt::JobSession job;  // joins the MPI job under mpirun or srun (host/mpi/job.h)
    const int status = mcrt::run_cli(argc, argv);
    mcrt::test_pause("exit");
    return status;
}
