#include "mpi/remote_worker.h"

#include <algorithm>
#include <chrono>

#include "common/error.h"
#include "mpi/mpi_comm.h"
#include "mpi/wire.h"

namespace mcrt {

RemoteWorker::RemoteWorker(int rank, int slot, int index, const std::string& name,
                           RankTraffic* traffic)
    : rank_(rank), slot_(slot), traffic_(traffic) {
    report.rank = rank;
    report.index = index;
    report.name = name;
}

RemoteWorker::~RemoteWorker() {
    if (failed_ || traffic_->lost) return;
    try {
        mpi::send_bytes(wire::encode_item(std::nullopt), rank_, mpi::item_tag(slot_));
    } catch (const std::exception&) {
        // MPI's own errors end the job (MPI_ERRORS_ARE_FATAL): nothing is left to tell.
    }
}

BatchResult RemoteWorker::run(const WorkItem& item) {
    auto start = std::chrono::steady_clock::now();
    const wire::Bytes request = wire::encode_item(item);
    mpi::send_bytes(request, rank_, mpi::item_tag(slot_));
    // An item takes about 150 ms: a rank silent for minutes is dead or hung. Only an MPI job
    // that outlives a process (mpirun --enable-recovery) lets rank 0 get this far.
    const double timeout = std::max(mpi::silence_timeout(), 20 * last_run_);
    std::optional<wire::Bytes> received =
        mpi::receive_bytes_within(rank_, mpi::result_tag(slot_), timeout);
    if (!received) {
        failed_ = true;
        traffic_->lost = true;
        throw RuntimeError("rank " + std::to_string(rank_) + " sent nothing for " +
                           std::to_string(int(timeout)) + " s and is taken for dead");
    }
    const wire::Bytes& reply = *received;
    double round_trip =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    wire::ResultMessage m = wire::decode_result(reply, item);
    if (m.failed) {
        failed_ = true;  // that rank's device thread has ended
        throw RuntimeError(m.error);
    }
    target_ = m.target_samples;
    last_run_ = m.seconds_run;
    pending_samples_ = m.samples;
    pending_busy_ = m.seconds_busy;
    pending_bytes_ = request.size() + reply.size();
    pending_overhead_ = std::max(0.0, round_trip - m.seconds_run);
    return std::move(m.result);
}

void RemoteWorker::commit_report() {
    report.seconds_busy += pending_busy_;
    report.samples += pending_samples_;
    report.batches += 1;
    traffic_->bytes += pending_bytes_;
    traffic_->seconds_overhead += pending_overhead_;
}

}  // namespace mcrt
