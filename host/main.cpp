#include "cli/cli.h"
#include "common/stop_signals.h"
#include "common/test_hooks.h"
#include "mpi/job.h"

int main(int argc, char** argv) {
    mcrt::ignore_pipe_signals();
    mcrt::JobSession job;  // joins the MPI job under mpirun or srun (host/mpi/job.h)
    const int status = mcrt::run_cli(argc, argv);
    mcrt::test_pause("exit");
    return status;
}
