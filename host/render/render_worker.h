// What the scheduler (render() in renderer.cpp) drives: a local device (DeviceWorker), or a
// device of another MPI rank seen from rank 0 (host/mpi/remote_worker.h).
#pragma once

#include <cstdint>

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

    DeviceReport report;
};

}  // namespace mcrt
