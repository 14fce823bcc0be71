#include "render/device_worker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "cl/cl_error.h"
#include "cl/program.h"
#include "common/error.h"
#include "common/test_hooks.h"
#include "render/plan.h"
#include "render/render_program.h"

namespace mcrt {

namespace {

double event_seconds(const cl::Event& event) {
    cl_ulong start = 0, end = 0;
    CL_CHECK(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
    CL_CHECK(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
    return double(end - start) * 1e-9;
}

cl::Buffer device_buffer(const DeviceContext& device, cl_mem_flags flags, size_t bytes,
                         const char* what) {
    cl_int status = CL_SUCCESS;
    cl::Buffer buffer(device.context, flags, bytes, nullptr, &status);
    CL_CHECK_STATUS(status, (std::string("clCreateBuffer(") + what + ")").c_str());
    return buffer;
}

constexpr size_t kGroupSize = 64;

uint64_t round_up(uint64_t n, uint64_t m) { return (n + m - 1) / m * m; }

// A launch should take about this long: long enough to hide launch overhead, short enough to
// balance devices and to stop promptly.
constexpr double kTargetLaunchSeconds = 0.15;

}  // namespace

void bind_render_arguments(cl::Kernel& render, const GpuSceneBuffers& scene,
                           const cl::Buffer& environment, const cl::Buffer& samples) {
    CL_CHECK(render.setArg(gpu::RENDER_ARG_NODES, scene.nodes));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_PACKETS, scene.packets));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_TRIANGLE_INFO, scene.triangle_info));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_MATERIALS, scene.materials));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_LIGHTS, scene.lights));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_LIGHT_SELECTION, scene.light_selection));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_SURFACES, scene.surfaces));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_TEXTURES, scene.textures));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_ENVIRONMENT, environment));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_PUNCTUAL, scene.punctual));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_CAMERA, scene.camera));
    CL_CHECK(render.setArg(gpu::RENDER_ARG_SAMPLES, samples));
}

cl::Buffer upload_environment(const DeviceContext& device, const EnvironmentLight* environment) {
    const std::vector<float> words =
        environment ? environment_words(*environment) : std::vector<float>(1, 0.0f);
    const size_t bytes = words.size() * sizeof(float);
    if (bytes > device.info.max_allocation)
        throw RuntimeError("the environment map needs " + std::to_string(bytes) +
                           " bytes, more than the " + std::to_string(device.info.max_allocation) +
                           " bytes device '" + device.info.name + "' can allocate at once");
    cl_int status = CL_SUCCESS;
    cl::Buffer buffer(device.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes,
                      const_cast<float*>(words.data()), &status);
    CL_CHECK_STATUS(status, "clCreateBuffer(environment map)");
    return buffer;
}

DeviceWorker::DeviceWorker(const DeviceContext& device, const GpuSceneData& scene,
                           const RenderPlan& plan)
    : device_(device),
      settings_(plan.settings),
      fixed_batch_(plan.fixed_batch),
      fail_at_launch_(test_fault_launch(device.info.index)),
      slow_factor_(test_slow_factor(device.info.index)) {
    build(plan);
    buffers_ = std::make_unique<GpuSceneBuffers>(device, scene, plan.variants.light_select->id);
    set_up(plan);
}

DeviceWorker::DeviceWorker(const DeviceContext& device, const GpuSceneBuffers& scene,
                           const RenderPlan& plan, const cl::Buffer& environment)
    : device_(device),
      settings_(plan.settings),
      fixed_batch_(plan.fixed_batch),
      fail_at_launch_(test_fault_launch(device.info.index)),
      slow_factor_(test_slow_factor(device.info.index)) {
    build(plan);
    buffers_ = std::make_unique<GpuSceneBuffers>(scene);  // handles: the buffers are shared
    environment_ = environment;
    set_up(plan);
}

void DeviceWorker::build(const RenderPlan& plan) {
    report.name = device_.info.name;
    report.index = device_.info.index;
    cl::Program program = render_program(device_, plan);
    render_ = make_kernel(program, "render");
    reduce_ = make_kernel(program, "reduce_chunks");
}

void DeviceWorker::set_up(const RenderPlan& plan) {
    const DeviceContext& device = device_;
    const RenderSettings& settings = plan.settings;
    // Batch buffers: at most 2^22 samples (64 MiB; a 150 ms launch needs far fewer on today's
    // devices) or a quarter of an allocation, whichever is less.
    max_samples_ =
        std::min<uint64_t>(uint64_t(1) << 22, device.info.max_allocation / 4 / sizeof(gpu::float4));
    if (fixed_batch_ > 0) max_samples_ = std::max(max_samples_, fixed_batch_);
    // The environment map: the one given (a session's), else uploaded for this render.
    if (plan.environment) {
        const EnvironmentLight& env = *plan.environment;
        environment_width_ = uint32_t(env.map.width);
        environment_height_ = uint32_t(env.map.height);
        const double turn = double(env.rotate_deg) * (3.14159265358979323846 / 180.0);
        environment_cos_ = float(std::cos(turn));
        environment_sin_ = float(std::sin(turn));
        environment_pmf_ = float(plan.environment_steps) * 0x1.0p-24f;  // exact: a grid value
    }
    if (!environment_()) environment_ = upload_environment(device, plan.environment.get());
    const size_t env_bytes = environment_.getInfo<CL_MEM_SIZE>();
    // Samples and, at 16 samples a chunk, their runs' sums (grown on demand when spp < 16).
    uint64_t needed =
        buffers_->bytes + env_bytes + max_samples_ * sizeof(gpu::float4) +
        (max_samples_ / MCRT_SAMPLES_PER_CHUNK + 1) * settings.replicates * sizeof(gpu::ChunkSums);
    if (needed > device.info.global_memory)
        throw RuntimeError(
            "device '" + device.info.name + "' has " + std::to_string(device.info.global_memory) +
            " bytes of memory; the scene and batch buffers need " + std::to_string(needed));
    samples_ = device_buffer(device, CL_MEM_READ_WRITE,
                             round_up(max_samples_, kGroupSize) * sizeof(gpu::float4), "samples");

    bind_render_arguments(render_, *buffers_, environment_, samples_);
    CL_CHECK(reduce_.setArg(0, samples_));
    CL_CHECK(reduce_.setArg(3, cl_uint(settings.replicates)));
}

DeviceWorker::~DeviceWorker() {
    if (!launches_in_flight_.empty()) device_.queue.finish();  // a failure: nothing to report
}

void DeviceWorker::reserve_sums(uint64_t runs) {
    if (runs <= sums_capacity_) return;
    sums_capacity_ = std::max<uint64_t>(runs, max_samples_ / MCRT_SAMPLES_PER_CHUNK);
    sums_ = device_buffer(device_, CL_MEM_WRITE_ONLY, sums_capacity_ * sizeof(gpu::ChunkSums),
                          "chunk sums");
    CL_CHECK(reduce_.setArg(4, sums_));
}

uint64_t DeviceWorker::target_samples() const {
    if (fixed_batch_ > 0) return fixed_batch_;
    if (report.seconds_busy <= 0) return 1024;  // the probe failed to measure anything
    double rate = double(report.samples) / (report.seconds_busy * slow_factor_);
    // At most four times the largest launch so far: a first launch's time measures a slow
    // device poorly (its build, its first specialisation), and one long launch cannot be stopped.
    const uint64_t grown = std::max<uint64_t>(1024, 4 * largest_launch_);
    return std::clamp<uint64_t>(uint64_t(rate * kTargetLaunchSeconds), 1024,
                                std::min(max_samples_, grown));
}

BatchResult DeviceWorker::run(const WorkItem& item) {
    start(item);
    return finish();
}

void DeviceWorker::start(const WorkItem& item) {
    const uint32_t sample_begin = item.chunk_begin * MCRT_SAMPLES_PER_CHUNK;
    const uint32_t sample_end =
        std::min<uint32_t>(item.chunk_end * MCRT_SAMPLES_PER_CHUNK, settings_.spp);
    const cl_uint n = sample_end - sample_begin;
    const uint64_t samples = uint64_t(item.pixel_count()) * n;
    if (samples > max_samples_)
        throw RuntimeError("batch of " + std::to_string(samples) + " samples exceeds the " +
                           std::to_string(max_samples_) + " the buffers of '" + report.name +
                           "' hold");
    if (++launches_ == fail_at_launch_)
        throw ClError("clEnqueueNDRangeKernel (injected by MCRT_FAULT_INJECT)", CL_OUT_OF_RESOURCES,
                      __FILE__, __LINE__);

    gpu::RenderParams params{};
    params.sky = {settings_.sky.r, settings_.sky.g, settings_.sky.b,
                  environment_.get() && environment_width_ > 0
                      ? environment_pmf_
                      : sky_light_pmf(settings_, buffers_->light_count + buffers_->punctual_count)};
    params.env_width = environment_width_;
    params.env_height = environment_height_;
    params.env_cos_rot = environment_cos_;
    params.env_sin_rot = environment_sin_;
    params.ao_distance = settings_.ao_distance;
    params.width = uint32_t(settings_.width);
    params.height = uint32_t(settings_.height);
    params.seed = settings_.seed;
    params.spp = settings_.spp;
    params.light_count = buffers_->light_count;
    params.light_tree_nodes = buffers_->light_tree_nodes;
    params.punctual_count = buffers_->punctual_count;
    params.pixel_begin = item.pixel_begin;
    params.pixel_end = item.pixel_end;
    params.sample_begin = sample_begin;
    params.batch_samples = n;
    params.replicates = settings_.replicates;
    params.max_depth = settings_.max_depth;
    params.rr_depth = settings_.rr_depth;
    // Arguments are captured at each enqueue: changing them for the next item is safe while
    // this one is in flight.
    CL_CHECK(render_.setArg(gpu::RENDER_ARG_PARAMS, sizeof params, &params));
    const cl_uint chunks = item.chunk_count();
    const uint64_t runs = uint64_t(item.pixel_count()) * chunks * settings_.replicates;
    reserve_sums(runs);  // a replaced buffer lives on until the commands using it are done
    CL_CHECK(reduce_.setArg(1, n));
    CL_CHECK(reduce_.setArg(2, cl_uint(item.pixel_count())));

    launches_in_flight_.emplace_back();
    Launch& launch = launches_in_flight_.back();
    launch.result.item = item;
    launch.result.sums.resize(runs);
    launch.samples = samples;
    try {
        // A fixed work-group size: PoCL specialises a kernel per local size, and a NULL local
        // size lets it pick a new one for each global size (a compile per launch).
        CL_CHECK(device_.queue.enqueueNDRangeKernel(
            render_, cl::NullRange, cl::NDRange(round_up(samples, kGroupSize)),
            cl::NDRange(kGroupSize), nullptr, &launch.render_done));
        CL_CHECK(device_.queue.enqueueNDRangeKernel(
            reduce_, cl::NullRange,
            cl::NDRange(round_up(uint64_t(item.pixel_count()) * chunks, kGroupSize)),
            cl::NDRange(kGroupSize), nullptr, &launch.reduce_done));
        CL_CHECK(device_.queue.enqueueReadBuffer(sums_, CL_FALSE, 0, runs * sizeof(gpu::ChunkSums),
                                                 launch.result.sums.data(), nullptr,
                                                 &launch.read_done));
        CL_CHECK(device_.queue.flush());  // start now, not at the next blocking call
    } catch (...) {
        launches_in_flight_.pop_back();
        throw;
    }
}

BatchResult DeviceWorker::finish() {
    Launch launch = std::move(launches_in_flight_.front());
    launches_in_flight_.pop_front();
    CL_CHECK(launch.read_done.wait());
    double busy = event_seconds(launch.render_done) + event_seconds(launch.reduce_done);
    if (slow_factor_ > 1.0)  // simulate a slower device (MCRT_SLOW_DEVICE)
        std::this_thread::sleep_for(std::chrono::duration<double>(busy * (slow_factor_ - 1.0)));
    // Counted into the report by commit_report(), under the lock the progress reads it with.
    pending_busy_ = busy;
    pending_samples_ = launch.samples;
    return std::move(launch.result);
}

void DeviceWorker::commit_report() {
    report.seconds_busy += pending_busy_;
    report.samples += pending_samples_;
    largest_launch_ = std::max(largest_launch_, pending_samples_);
    report.batches += 1;
}

}  // namespace mcrt
