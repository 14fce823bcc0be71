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
    // Waited for in slices, so that a stop (stopping()) cuts the wait short.
    std::optional<wire::Bytes> received;
    bool cut_by_stop = false;
    for (;;) {
        const auto now = std::chrono::steady_clock::now();
        const double waited = std::chrono::duration<double>(now - start).count();
        const int64_t deadline = stop_deadline_.load();
        cut_by_stop = deadline != 0 && now.time_since_epoch().count() >= deadline;
        if (waited >= timeout || cut_by_stop) break;
        received = mpi::receive_bytes_within(rank_, mpi::result_tag(slot_),
                                             std::min(0.25, timeout - waited));
        if (received) break;
    }
    if (!received) {
        failed_ = true;
        traffic_->lost = true;
        const double waited =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        throw RuntimeError(
            "rank " + std::to_string(rank_) + " sent nothing for " + std::to_string(int(waited)) +
            " s" + (cut_by_stop ? " after the render stopped" : "") + " and is taken for dead");
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

void RemoteWorker::stopping(double seconds) {
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(seconds));
    stop_deadline_.store(deadline.time_since_epoch().count());
}

void RemoteWorker::commit_report() {
    report.seconds_busy += pending_busy_;
    report.samples += pending_samples_;
    report.batches += 1;
    traffic_->bytes += pending_bytes_;
    traffic_->seconds_overhead += pending_overhead_;
}

}  // namespace mcrt
