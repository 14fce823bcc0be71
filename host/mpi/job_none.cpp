// mcrt built without MPI: every process is a job of one (host/mpi/job.h).
#include "common/error.h"
#include "mpi/job.h"

namespace mcrt {

struct RenderJob::State {};

JobSession::JobSession() = default;
JobSession::~JobSession() = default;
int job_rank() { return 0; }
int job_size() { return 1; }
int agree_on_command(const std::vector<std::string>&, const std::string&) { return 0; }

RenderJob::RenderJob() { throw RuntimeError("mcrt was built without MPI"); }
RenderJob::~RenderJob() = default;
void RenderJob::share_inputs(const FileBundle&, const std::string&) {}
RemoteWorkers RenderJob::remote_workers(std::function<void(const std::string&)>) { return {}; }
nlohmann::json RenderJob::ranks_json(const std::vector<DeviceReport>&) const { return {}; }
void RenderJob::finish(int, const std::string&) {}
int serve_render(const std::function<RenderRequest()>&, const std::vector<std::string>&) {
    throw RuntimeError("mcrt was built without MPI");
}

}  // namespace mcrt
