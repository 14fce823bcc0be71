// One render across the processes of an MPI job (docs/MPI.md). Built with MPI when CMake finds
// it (MCRT_HAVE_MPI); without it, or when mcrt is not started by mpirun or srun, every process is
// a job of one and renders as it always has.
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/plan.h"
#include "render/renderer.h"
#include "scene/gltf_import.h"

namespace mcrt {

// Joins the MPI job for the life of the process when an MPI launcher started it (mpirun's
// OMPI_COMM_WORLD_SIZE, PMIx's PMIX_RANK or PMI's PMI_RANK in the environment); otherwise does
// nothing, so a plain `mcrt` never initialises MPI.
class JobSession {
  public:
    JobSession();
    ~JobSession();
    JobSession(const JobSession&) = delete;
    JobSession& operator=(const JobSession&) = delete;
};

int job_rank();  // this process's rank; 0 outside a job
int job_size();  // processes in the job; 1 outside one

// First thing after the command line is read, in a job of more than one rank: every rank's
// reading of it against rank 0's, so that no rank renders with options of its own and none is
// left waiting for a rank that refused its options (docs/MPI.md). `command` is this rank's
// reading, one entry per option as it reads ("mcrt render", "--width 64", "no --png"; rank 0's
// and every other rank's lists have the same length when they run the same subcommand);
// `refused` is this rank's usage error, if any. Rank 0 prints one `mcrt: error:` line for the
// lowest rank that refused its options or reads one differently (its own usage error is its
// caller's to print). Returns the status every rank exits with: 0 when all agree, else 2.
int agree_on_command(const std::vector<std::string>& command, const std::string& refused);

// Rank 0's side of a render across the job: it sends the inputs, hands every other rank's devices
// work items (RemoteWorker) beside its own, and tells the ranks how the command ended.
class RenderJob {
  public:
    RenderJob();
    ~RenderJob();
    RenderJob(const RenderJob&) = delete;
    RenderJob& operator=(const RenderJob&) = delete;

    // Broadcasts the scene's files and the estimator's text (after rank 0 checked them).
    void share_inputs(const FileBundle& files, const std::string& estimator_source);

    // For render(): waits for every rank's setup and returns one worker per device of theirs;
    // prints the ranks' setup warnings through `warn`.
    RemoteWorkers remote_workers(std::function<void(const std::string&)> warn);

    // `ranks` of the stats JSON: per rank, its host, devices, samples, items and busy time.
    nlohmann::json ranks_json(const std::vector<DeviceReport>& devices) const;

    // The command's exit status, to every rank (they exit with it); then the job is over.
    // `error` is the command's error line, printed here only when a lost rank forces MPI_Abort.
    // With a rank lost, ends the process with MPI_Abort: status 3 when the outputs were written.
    void finish(int status, const std::string& error = "");

  private:
    struct State;
    std::unique_ptr<State> state_;
};

// Every rank but 0: receives the inputs, sets up its devices, renders the items rank 0 hands
// them until told to stop, and returns rank 0's exit status. Prints nothing: what goes wrong
// here reaches rank 0 as a warning (a setup that fails, a device that fails) and its status.
// `make_request` and `devices` are this rank's own reading of the command line (the same on every
// rank but --device: agree_on_command); the scene and the estimator's text come from rank 0.
// The request is made only once rank 0 says go: a request rank 0 refused (a bad --sky) ends this
// rank with rank 0's status and no line of its own.
int serve_render(const std::function<RenderRequest()>& make_request,
                 const std::vector<std::string>& devices);

}  // namespace mcrt
