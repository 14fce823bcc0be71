// What the scheduler (render() in renderer.cpp) drives: a local device (DeviceWorker), or a
// device of another MPI rank seen from rank 0 (host/mpi/remote_worker.h).
#pragma once

#include <cstdint>
#include <deque>

#include "render/accumulator.h"
#include "render/renderer.h"
#include "render/work_queue.h"

namespace mcrt {

class RenderWorker {
  public:
    virtual ~RenderWorker() = default;

    // Samples the next item should hold (the device's measured speed over about 150 ms).
    virtual uint64_t target_samples() const = 0;

    // Renders one work item and returns its per-chunk sums; throws RuntimeError when the device
    // fails (the scheduler then retires it and redoes the item elsewhere).
    virtual BatchResult run(const WorkItem& item) = 0;

    // Adds the last successful run to `report`; the caller holds the render's lock.
    virtual void commit_report() = 0;

    // Pipelining: start() begins an item without waiting for it, finish() waits for the oldest
    // started one and returns its sums (both throw as run does). The scheduler keeps up to
    // pipeline_depth() items started, so that a device renders the next item while the host
    // reads and adds the last. By default one at a time: start() keeps the item, finish() runs
    // it.
    virtual size_t pipeline_depth() const { return 1; }
    virtual void start(const WorkItem& item) { started_.push_back(item); }
    virtual BatchResult finish() {
        WorkItem item = started_.front();
        started_.pop_front();
        return run(item);
    }

    // The render has stopped (time limit or interrupt): an item still in flight that has not
    // returned within `seconds` may be given up. Called from the render's own thread; a local
    // device cannot be cut short and ignores it, another rank's device does not wait longer.
    virtual void stopping(double /*seconds*/) {}

    DeviceReport report;

  private:
    std::deque<WorkItem> started_;
};

}  // namespace mcrt
