// One device's part of a render: its copy of the scene, its compiled render and reduction
// kernels, its batch buffers and its measured speed (the scheduler is in renderer.cpp).
#pragma once

#include <CL/opencl.hpp>
#include <cstdint>
#include <deque>
#include <memory>

#include "cl/device.h"
#include "render/accumulator.h"
#include "render/gpu_scene.h"
#include "render/plan.h"
#include "render/render_worker.h"
#include "render/renderer.h"
#include "render/work_queue.h"

namespace mcrt {

// Binds the render kernel's buffers in the order of RenderArgument (kernels/core/shared_types.h);
// the per-launch RenderParams are set with each launch.
void bind_render_arguments(cl::Kernel& render, const GpuSceneBuffers& scene,
                           const cl::Buffer& environment, const cl::Buffer& samples);

// The environment map's texels and CDF on the device (RENDER_ARG_ENVIRONMENT), one float when
// there is no map; RuntimeError when the device cannot allocate them at once.
cl::Buffer upload_environment(const DeviceContext& device, const EnvironmentLight* environment);

class DeviceWorker : public RenderWorker {
  public:
    // Builds the program, uploads the scene and allocates the batch buffers; throws RuntimeError
    // when the device cannot hold them, InputError for a user's estimator that does not build.
    // The plan's fixed_batch > 0 makes every launch that many samples (--batch). `plan` must
    // outlive the worker.
    DeviceWorker(const DeviceContext& device, const GpuSceneData& scene, const RenderPlan& plan);
    // The same on a scene already on the device (a session's, render/session.h): `scene` holds
    // the light selection's buffer of the plan and the camera of the render; `environment`, when
    // not null, is the plan's environment map already on the device (upload_environment).
    DeviceWorker(const DeviceContext& device, const GpuSceneBuffers& scene, const RenderPlan& plan,
                 const cl::Buffer& environment = cl::Buffer());
    // Waits for the commands still in flight: they write into this worker's host memory.
    ~DeviceWorker() override;

    // Samples the next launch should hold: a fixed --batch, else a probe, then what the
    // measured speed does in about 150 ms, growing at most fourfold from launch to launch.
    uint64_t target_samples() const override;

    // Renders and reduces one work item; throws RuntimeError when the device fails.
    BatchResult run(const WorkItem& item) override;

    // Two items in flight: the in-order queue runs the second's kernels while the host takes the
    // first's sums (the samples buffer is shared: the queue's order keeps the second render
    // after the first reduction, and each item reads into its own host memory).
    size_t pipeline_depth() const override { return 2; }
    void start(const WorkItem& item) override;
    BatchResult finish() override;

    // Adds the last successful launch to the report; the caller holds the render's lock.
    void commit_report() override;

  private:
    // Makes the sums buffer hold `runs` ChunkSums, reallocating when it is smaller.
    void reserve_sums(uint64_t runs);
    // The constructors' common part: the program, the batch buffers, the kernels' arguments.
    void build(const RenderPlan& plan);
    void set_up(const RenderPlan& plan);

  private:
    const DeviceContext& device_;
    const RenderSettings& settings_;
    uint64_t fixed_batch_;
    uint64_t fail_at_launch_;  // test hooks (common/test_hooks.h)
    double slow_factor_;
    uint64_t max_samples_ = 0;
    uint64_t launches_ = 0;
    double pending_busy_ = 0;
    uint64_t pending_samples_ = 0;
    uint64_t largest_launch_ = 0;  // samples of the largest committed launch
    cl::Kernel render_, reduce_;
    std::unique_ptr<GpuSceneBuffers> buffers_;
    cl::Buffer samples_, sums_;
    // The environment map's texels and CDF (RENDER_ARG_ENVIRONMENT; one float without --env),
    // its size, turn and the probability that the light strategies choose it.
    cl::Buffer environment_;
    uint32_t environment_width_ = 0, environment_height_ = 0;
    float environment_cos_ = 1.0f, environment_sin_ = 0.0f, environment_pmf_ = 0.0f;
    uint64_t sums_capacity_ = 0;  // ChunkSums the sums_ buffer holds
    struct Launch {  // a started item: its result (sums read into it) and its commands' events
        BatchResult result;
        uint64_t samples = 0;
        cl::Event render_done, reduce_done, read_done;
    };
    std::deque<Launch> launches_in_flight_;
};

}  // namespace mcrt
