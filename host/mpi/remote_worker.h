// Rank 0's view of one device of another rank: the scheduler hands it work items like a local
// device; each is sent to that rank, which renders it and sends back its sums (built with MPI).
#pragma once

#include <atomic>
#include <string>

#include "render/render_worker.h"

namespace mcrt {

// What rank 0 measured of its messages with one rank, for the stats and docs/BENCHMARKS.md.
struct RankTraffic {
    uint64_t bytes = 0;           // items sent and results received
    double seconds_overhead = 0;  // per item: round trip minus the item's wall time there
    bool lost = false;            // fell silent (mpi::silence_timeout()): taken for dead
};

class RemoteWorker : public RenderWorker {
  public:
    // Device `slot` of rank `rank` (its index there `index`, its name `name`); `traffic` is
    // counted in commit_report, under the render's lock.
    RemoteWorker(int rank, int slot, int index, const std::string& name, RankTraffic* traffic);
    // Tells the device the render is over, unless it failed (its rank no longer listens).
    ~RemoteWorker() override;

    uint64_t target_samples() const override { return target_; }
    // Sends the item and waits for its result; a device that failed there throws RuntimeError
    // with its error, and the scheduler retires it; so does a rank silent for longer than
    // mpi::silence_timeout() (and the whole rank is lost: it is not told to stop).
    BatchResult run(const WorkItem& item) override;
    void commit_report() override;
    // After a stop an item is waited for `seconds` more at most, so that a rank that died during
    // the stop is taken for dead before the supervisor's grace period ends.
    void stopping(double seconds) override;

  private:
    int rank_, slot_;
    RankTraffic* traffic_;
    bool failed_ = false;
    uint64_t target_ = 1024;
    uint64_t pending_samples_ = 0, pending_bytes_ = 0;
    double pending_busy_ = 0, pending_overhead_ = 0;
    double last_run_ = 0;  // the last item's wall time on that rank
    // steady_clock nanoseconds after which an item is not waited for (stopping()); 0: none.
    std::atomic<int64_t> stop_deadline_{0};
};

}  // namespace mcrt
