#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <thread>

#include "cl/cl_error.h"
#include "cl/program.h"
#include "common/error.h"
#include "render/accumulator.h"
#include "render/work_queue.h"

namespace mcrt {

const std::vector<std::string> kEstimators = {
    "hemisphere-uniform", "hemisphere-cosine", "light-area",      "light-solid-angle", "mis",
    "ambient-uniform",    "ambient-cosine",    "ambient-fibonacci"};

std::string render_program_options(const RenderSettings& settings) {
    if (std::find(kEstimators.begin(), kEstimators.end(), settings.estimator) == kEstimators.end())
        throw InputError("--estimator " + settings.estimator + ": unknown estimator");
    // "light-solid-angle" → ESTIMATOR_LIGHT_SOLID_ANGLE
    std::string macro = "ESTIMATOR_";
    for (char c : settings.estimator) macro += c == '-' ? '_' : char(std::toupper(c));
    std::string options = "-cl-std=CL1.2 -D " + macro;
    switch (settings.light_select) {
        case LightSelect::Uniform: options += " -D LIGHT_SELECT_UNIFORM"; break;
        case LightSelect::Power: options += " -D LIGHT_SELECT_POWER"; break;
        case LightSelect::Alias: options += " -D LIGHT_SELECT_ALIAS"; break;
    }
    switch (settings.sampler) {
        case SamplerKind::Independent: options += " -D SAMPLER_INDEPENDENT"; break;
        case SamplerKind::Stratified: options += " -D SAMPLER_STRATIFIED"; break;
        case SamplerKind::Sobol: options += " -D SAMPLER_SOBOL"; break;
    }
    if (settings.estimator == "mis")
        options += settings.mis_heuristic == MisHeuristic::Power ? " -D MIS_POWER" : " -D MIS_BALANCE";
    return options;
}

uint32_t batch_samples_per_pixel(uint32_t requested, int width, int height, uint32_t spp) {
    const uint32_t chunk = MCRT_SAMPLES_PER_CHUNK;
    uint64_t batch = requested;
    if (batch == 0) batch = (uint64_t(1) << 22) / (uint64_t(width) * height);
    batch = std::max<uint64_t>(chunk, (batch + chunk - 1) / chunk * chunk);
    uint64_t spp_chunks = (uint64_t(spp) + chunk - 1) / chunk * chunk;
    return uint32_t(std::min(batch, spp_chunks));
}

static double event_seconds(const cl::Event& event) {
    cl_ulong start = 0, end = 0;
    CL_CHECK(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
    CL_CHECK(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
    return double(end - start) * 1e-9;
}

static cl::Buffer device_buffer(const DeviceContext& device, cl_mem_flags flags, size_t bytes,
                                const char* what) {
    cl_int status = CL_SUCCESS;
    cl::Buffer buffer(device.context, flags, bytes, nullptr, &status);
    CL_CHECK_STATUS(status, (std::string("clCreateBuffer(") + what + ")").c_str());
    return buffer;
}

namespace {

// "D:V" from an environment variable: device index D and a value, for testing and simulation.
bool device_switch(const char* name, int device_index, double* value) {
    const char* text = std::getenv(name);
    if (!text) return false;
    int d = -1;
    double v = 0;
    if (std::sscanf(text, "%d:%lf", &d, &v) != 2 || d != device_index) return false;
    *value = v;
    return true;
}

constexpr size_t kGroupSize = 64;

uint64_t round_up(uint64_t n, uint64_t m) { return (n + m - 1) / m * m; }

// A launch should take about this long: long enough to hide launch overhead, short enough to
// balance devices and to stop promptly.
constexpr double kTargetLaunchSeconds = 0.15;

// One device's copy of the scene, its kernels and buffers, and its measured speed.
class DeviceWorker {
public:
    DeviceWorker(const DeviceContext& device, const GpuSceneData& scene,
                 const RenderSettings& settings, uint64_t fixed_batch_samples)
        : device_(device), settings_(settings), fixed_batch_(fixed_batch_samples) {
        report.name = device.info.name;
        report.index = device.info.index;
        double v;
        if (device_switch("MCRT_FAULT_INJECT", device.info.index, &v)) fail_at_launch_ = uint64_t(v);
        if (device_switch("MCRT_SLOW_DEVICE", device.info.index, &v)) slow_factor_ = std::max(1.0, v);

        cl::Program program = cached_program(device, "render.cl", render_program_options(settings));
        render_ = make_kernel(program, "render");
        reduce_ = make_kernel(program, "reduce_chunks");
        buffers_ = std::make_unique<GpuSceneBuffers>(device, scene);

        // Batch buffers: at most 2^22 samples (64 MiB; a 150 ms launch needs far fewer on today's
        // devices) or a quarter of an allocation, whichever is less.
        max_samples_ = std::min<uint64_t>(uint64_t(1) << 22, device.info.max_allocation / 4 / sizeof(gpu::float4));
        if (fixed_batch_ > 0) max_samples_ = std::max(max_samples_, fixed_batch_);
        uint64_t needed = buffers_->bytes + max_samples_ * sizeof(gpu::float4) * 3;
        if (needed > device.info.global_memory)
            throw RuntimeError("device '" + device.info.name + "' has " +
                               std::to_string(device.info.global_memory) +
                               " bytes of memory; the scene and batch buffers need " +
                               std::to_string(needed));
        samples_ = device_buffer(device, CL_MEM_READ_WRITE, round_up(max_samples_, kGroupSize) * sizeof(gpu::float4), "samples");
        // Up to one sum per sample, when spp < one chunk.
        sums_ = device_buffer(device, CL_MEM_WRITE_ONLY, max_samples_ * sizeof(gpu::float4), "sums");
        sums_sq_ = device_buffer(device, CL_MEM_WRITE_ONLY, max_samples_ * sizeof(gpu::float4), "sums");

        const cl_float4 sky = {{settings.sky.r, settings.sky.g, settings.sky.b, 0.0f}};
        CL_CHECK(render_.setArg(0, buffers_->nodes));
        CL_CHECK(render_.setArg(1, buffers_->packets));
        CL_CHECK(render_.setArg(2, buffers_->triangle_info));
        CL_CHECK(render_.setArg(3, buffers_->materials));
        CL_CHECK(render_.setArg(4, buffers_->lights));
        CL_CHECK(render_.setArg(5, buffers_->light_cdf));
        CL_CHECK(render_.setArg(6, buffers_->light_alias));
        CL_CHECK(render_.setArg(7, buffers_->light_count));
        CL_CHECK(render_.setArg(8, buffers_->camera));
        CL_CHECK(render_.setArg(9, cl_uint(settings.width)));
        CL_CHECK(render_.setArg(10, cl_uint(settings.height)));
        CL_CHECK(render_.setArg(11, cl_uint(settings.seed)));
        CL_CHECK(render_.setArg(12, cl_uint(settings.spp)));
        CL_CHECK(render_.setArg(13, sky));
        CL_CHECK(render_.setArg(14, cl_float(settings.ao_distance)));
        CL_CHECK(render_.setArg(19, samples_));
        CL_CHECK(reduce_.setArg(0, samples_));
        CL_CHECK(reduce_.setArg(3, sums_));
        CL_CHECK(reduce_.setArg(4, sums_sq_));
    }

    // Samples the next launch should hold: a fixed --batch, else a probe, then what the
    // measured speed does in kTargetLaunchSeconds.
    uint64_t target_samples() const {
        if (fixed_batch_ > 0) return fixed_batch_;
        if (report.seconds_busy <= 0) return 1024;  // the probe failed to measure anything
        double rate = double(report.samples) / (report.seconds_busy * slow_factor_);
        return std::clamp<uint64_t>(uint64_t(rate * kTargetLaunchSeconds), 1024, max_samples_);
    }

    BatchResult run(const WorkItem& item, const WorkQueue& queue) {
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
            throw ClError("clEnqueueNDRangeKernel (injected by MCRT_FAULT_INJECT)",
                          CL_OUT_OF_RESOURCES, __FILE__, __LINE__);
        const cl_uint chunks = item.chunk_count();
        CL_CHECK(render_.setArg(15, cl_uint(item.pixel_begin)));
        CL_CHECK(render_.setArg(16, cl_uint(item.pixel_end)));
        CL_CHECK(render_.setArg(17, cl_uint(sample_begin)));
        CL_CHECK(render_.setArg(18, n));
        CL_CHECK(reduce_.setArg(1, n));
        CL_CHECK(reduce_.setArg(2, cl_uint(item.pixel_count())));
        cl::Event render_done, reduce_done;
        // A fixed work-group size: PoCL specialises a kernel per local size, and a NULL local
        // size lets it pick a new one for each global size (a compile per launch).
        CL_CHECK(device_.queue.enqueueNDRangeKernel(render_, cl::NullRange,
                                                    cl::NDRange(round_up(samples, kGroupSize)),
                                                    cl::NDRange(kGroupSize), nullptr, &render_done));
        CL_CHECK(device_.queue.enqueueNDRangeKernel(
            reduce_, cl::NullRange,
            cl::NDRange(round_up(uint64_t(item.pixel_count()) * chunks, kGroupSize)),
            cl::NDRange(kGroupSize), nullptr, &reduce_done));
        BatchResult result;
        result.item = item;
        result.sums.resize(size_t(item.pixel_count()) * chunks);
        result.sums_sq.resize(result.sums.size());
        size_t bytes = result.sums.size() * sizeof(gpu::float4);
        CL_CHECK(device_.queue.enqueueReadBuffer(sums_, CL_FALSE, 0, bytes, result.sums.data()));
        CL_CHECK(device_.queue.enqueueReadBuffer(sums_sq_, CL_TRUE, 0, bytes, result.sums_sq.data()));
        double busy = event_seconds(render_done) + event_seconds(reduce_done);
        if (slow_factor_ > 1.0)  // simulate a slower device (MCRT_SLOW_DEVICE)
            std::this_thread::sleep_for(std::chrono::duration<double>(busy * (slow_factor_ - 1.0)));
        // Counted into the report by commit_report(), under the lock the progress reads it with.
        pending_busy_ = busy;
        pending_samples_ = samples;
        (void)queue;
        return result;
    }

    // Adds the last successful launch to the report; the caller holds the render's lock.
    void commit_report() {
        report.seconds_busy += pending_busy_;
        report.samples += pending_samples_;
        report.batches += 1;
    }

    DeviceReport report;

private:
    const DeviceContext& device_;
    const RenderSettings& settings_;
    uint64_t fixed_batch_;
    uint64_t max_samples_ = 0;
    uint64_t launches_ = 0, fail_at_launch_ = 0;
    double slow_factor_ = 1.0;
    double pending_busy_ = 0;
    uint64_t pending_samples_ = 0;
    cl::Kernel render_, reduce_;
    std::unique_ptr<GpuSceneBuffers> buffers_;
    cl::Buffer samples_, sums_, sums_sq_;
};

}  // namespace

RenderResult render(const std::vector<const DeviceContext*>& devices, const GpuSceneData& scene,
                    const RenderSettings& settings, const ProgressSink& progress,
                    const RenderControl& control,
                    const std::function<void(const std::string&)>& warn) {
    auto start = std::chrono::steady_clock::now();
    render_program_options(settings);  // rejects unknown settings before any device work
    const uint32_t pixels = uint32_t(settings.width) * uint32_t(settings.height);
    const uint64_t fixed_batch =
        settings.batch > 0
            ? uint64_t(pixels) *
                  batch_samples_per_pixel(settings.batch, settings.width, settings.height, settings.spp)
            : 0;

    // Set up every device; one that cannot hold the scene is skipped with a warning.
    std::vector<std::unique_ptr<DeviceWorker>> workers;
    std::string last_error;
    for (const DeviceContext* d : devices) {
        try {
            workers.push_back(std::make_unique<DeviceWorker>(*d, scene, settings, fixed_batch));
        } catch (const RuntimeError& e) {
            if (devices.size() == 1) throw;
            last_error = e.what();
            if (warn) warn("skipping device " + std::to_string(d->info.index) + " ('" + d->info.name + "'): " + e.what());
        }
    }
    if (workers.empty()) throw RuntimeError("no device can render this scene: " + last_error);

    RenderResult result;
    result.seconds_build = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WorkQueue queue(pixels, settings.spp);
    Accumulator acc(pixels, settings.spp);
    std::mutex acc_mutex;

    auto device_reports = [&] {
        std::vector<DeviceReport> r;
        for (const auto& w : workers) r.push_back(w->report);
        return r;
    };
    auto device_loop = [&](DeviceWorker& worker, std::optional<WorkItem> item) {
        for (; item; item = queue.take(worker.target_samples())) {
            BatchResult r;
            try {
                r = worker.run(*item, queue);
            } catch (const RuntimeError& e) {
                std::lock_guard<std::mutex> lock(acc_mutex);
                worker.report.retired = true;
                if (warn) warn("device " + std::to_string(worker.report.index) + " ('" + worker.report.name + "') failed and is retired; its work is redone on the other devices: " + e.what());
                queue.give_back(*item);
                return;
            }
            std::lock_guard<std::mutex> lock(acc_mutex);
            worker.commit_report();
            acc.submit(std::move(r));
            queue.done(*item);
        }
    };
    // Every device starts with a probe launch handed out here, so each one measures its speed
    // and none is starved by a faster one that starts first; the probes leave most of the work
    // to the dynamic phase.
    const uint64_t total_samples = uint64_t(pixels) * settings.spp;
    const uint64_t probe = std::clamp<uint64_t>(total_samples / (8 * workers.size()), 1024, 1 << 16);
    std::vector<std::thread> threads;
    for (auto& w : workers)
        threads.emplace_back(device_loop, std::ref(*w),
                             queue.take(fixed_batch > 0 ? fixed_batch : probe));

    // Watch the clock, the interrupt flag and the progress until the devices are done.
    auto finished = [&] {
        for (const auto& w : workers)
            if (!w->report.retired) return false;
        return true;
    };
    for (;;) {
        {
            std::lock_guard<std::mutex> lock(acc_mutex);
            if (progress) progress(acc.committed_spp(), settings.spp, device_reports());
            if (acc.committed_spp() >= settings.spp || finished()) break;
        }
        double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (result.stopped_by.empty() && control.time_limit > 0 && elapsed >= control.time_limit) {
            result.stopped_by = "time limit";
            queue.stop();
        }
        if (result.stopped_by.empty() && control.interrupted && *control.interrupted) {
            result.stopped_by = "interrupt";
            queue.stop();
        }
        if (queue.stopped()) {
            // Wait for the threads: hand-out has stopped, in-flight work drains.
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    for (std::thread& t : threads) t.join();

    if (acc.committed_spp() == 0 || (result.stopped_by.empty() && acc.committed_spp() < settings.spp))
        throw RuntimeError("every device failed; no image was completed");
    if (progress) progress(acc.committed_spp(), settings.spp, device_reports());
    result.spp = acc.committed_spp();
    result.image = acc.image(settings.width, settings.height);
    result.nan_samples = acc.nan_samples();
    result.rays = acc.rays();
    result.devices = device_reports();
    for (const DeviceReport& d : result.devices) result.seconds_render += d.seconds_busy;
    return result;
}

RenderResult render(const DeviceContext& device, const GpuSceneData& scene,
                    const RenderSettings& settings) {
    return render(std::vector<const DeviceContext*>{&device}, scene, settings);
}

}  // namespace mcrt
