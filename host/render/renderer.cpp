#include "render/renderer.h"

#include <algorithm>
#include <chrono>

#include "cl/cl_error.h"
#include "cl/program.h"
#include "common/error.h"

namespace mcrt {

Accumulator::Accumulator(int width, int height)
    : width_(width), height_(height), sum_(3 * size_t(width) * height),
      sum_sq_(3 * size_t(width) * height) {}

void Accumulator::add_batch(const std::vector<gpu::float4>& sums,
                            const std::vector<gpu::float4>& sums_sq, uint32_t chunks) {
    size_t pixels = size_t(width_) * height_;
    for (size_t p = 0; p < pixels; ++p) {
        for (uint32_t c = 0; c < chunks; ++c) {
            const gpu::float4& s = sums[p * chunks + c];
            const gpu::float4& s2 = sums_sq[p * chunks + c];
            sum_[3 * p + 0] += s.x;
            sum_[3 * p + 1] += s.y;
            sum_[3 * p + 2] += s.z;
            sum_sq_[3 * p + 0] += s2.x;
            sum_sq_[3 * p + 1] += s2.y;
            sum_sq_[3 * p + 2] += s2.z;
            nan_samples_ += uint64_t(s.w);
            rays_ += uint64_t(s2.w);
        }
    }
}

Image Accumulator::image(uint32_t spp) const {
    Image img(width_, height_);
    img.spp = spp;
    if (spp == 0) return img;
    double n = spp;
    for (size_t k = 0; k < sum_.size(); ++k) {
        double mean = sum_[k] / n;
        img.rgb[k] = float(mean);
        // Variance of the pixel mean: the sample variance (n − 1 denominator) over n.
        double var = n > 1 ? std::max(0.0, (sum_sq_[k] - sum_[k] * mean) / (n - 1)) / n : 0.0;
        img.variance[k] = float(var);
    }
    return img;
}

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
    if (bytes > device.info.max_allocation)
        throw RuntimeError(std::string(what) + " needs " + std::to_string(bytes) +
                           " bytes, more than the " + std::to_string(device.info.max_allocation) +
                           " bytes device '" + device.info.name +
                           "' can allocate at once (lower --batch)");
    cl_int status = CL_SUCCESS;
    cl::Buffer buffer(device.context, flags, bytes, nullptr, &status);
    CL_CHECK_STATUS(status, (std::string("clCreateBuffer(") + what + ")").c_str());
    return buffer;
}

RenderResult render(const DeviceContext& device, const GpuSceneData& scene,
                    const RenderSettings& settings, const ProgressSink& progress) {
    RenderResult result;
    const int width = settings.width, height = settings.height;
    const cl_uint pixels = cl_uint(width) * cl_uint(height);
    const uint32_t batch = batch_samples_per_pixel(settings.batch, width, height, settings.spp);
    const uint32_t chunks = (batch + MCRT_SAMPLES_PER_CHUNK - 1) / MCRT_SAMPLES_PER_CHUNK;

    auto t0 = std::chrono::steady_clock::now();
    cl::Program program = cached_program(device, "render.cl", render_program_options(settings));
    result.seconds_build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cl::Kernel render_kernel = make_kernel(program, "render");
    cl::Kernel reduce_kernel = make_kernel(program, "reduce_chunks");

    GpuSceneBuffers buffers(device, scene);
    cl::Buffer samples = device_buffer(device, CL_MEM_READ_WRITE,
                                       size_t(pixels) * batch * sizeof(gpu::float4), "sample buffer");
    size_t sums_bytes = size_t(pixels) * chunks * sizeof(gpu::float4);
    cl::Buffer sums = device_buffer(device, CL_MEM_WRITE_ONLY, sums_bytes, "sum buffer");
    cl::Buffer sums_sq = device_buffer(device, CL_MEM_WRITE_ONLY, sums_bytes, "sum buffer");

    const cl_float4 sky = {{settings.sky.r, settings.sky.g, settings.sky.b, 0.0f}};
    CL_CHECK(render_kernel.setArg(0, buffers.nodes));
    CL_CHECK(render_kernel.setArg(1, buffers.triangles));
    CL_CHECK(render_kernel.setArg(2, buffers.materials));
    CL_CHECK(render_kernel.setArg(3, buffers.lights));
    CL_CHECK(render_kernel.setArg(4, buffers.light_cdf));
    CL_CHECK(render_kernel.setArg(5, buffers.light_alias));
    CL_CHECK(render_kernel.setArg(6, buffers.light_count));
    CL_CHECK(render_kernel.setArg(7, buffers.camera));
    CL_CHECK(render_kernel.setArg(8, cl_uint(width)));
    CL_CHECK(render_kernel.setArg(9, cl_uint(height)));
    CL_CHECK(render_kernel.setArg(10, cl_uint(settings.seed)));
    CL_CHECK(render_kernel.setArg(11, cl_uint(settings.spp)));
    CL_CHECK(render_kernel.setArg(12, sky));
    CL_CHECK(render_kernel.setArg(13, cl_float(settings.ao_distance)));
    CL_CHECK(render_kernel.setArg(16, samples));
    CL_CHECK(reduce_kernel.setArg(0, samples));
    CL_CHECK(reduce_kernel.setArg(2, pixels));
    CL_CHECK(reduce_kernel.setArg(3, sums));
    CL_CHECK(reduce_kernel.setArg(4, sums_sq));

    Accumulator acc(width, height);
    std::vector<gpu::float4> host_sums(size_t(pixels) * chunks), host_sums_sq(host_sums.size());
    DeviceReport report;
    report.name = device.info.name;
    for (uint32_t begin = 0; begin < settings.spp; begin += batch) {
        // Batches start on chunk boundaries: only the last may be shorter.
        const cl_uint n = std::min(batch, settings.spp - begin);
        const cl_uint n_chunks = (n + MCRT_SAMPLES_PER_CHUNK - 1) / MCRT_SAMPLES_PER_CHUNK;
        CL_CHECK(render_kernel.setArg(14, cl_uint(begin)));
        CL_CHECK(render_kernel.setArg(15, n));
        CL_CHECK(reduce_kernel.setArg(1, n));
        cl::Event render_done, reduce_done;
        CL_CHECK(device.queue.enqueueNDRangeKernel(render_kernel, cl::NullRange,
                                                   cl::NDRange(size_t(pixels) * n), cl::NullRange,
                                                   nullptr, &render_done));
        CL_CHECK(device.queue.enqueueNDRangeKernel(reduce_kernel, cl::NullRange,
                                                   cl::NDRange(size_t(pixels) * n_chunks),
                                                   cl::NullRange, nullptr, &reduce_done));
        size_t bytes = size_t(pixels) * n_chunks * sizeof(gpu::float4);
        CL_CHECK(device.queue.enqueueReadBuffer(sums, CL_FALSE, 0, bytes, host_sums.data()));
        CL_CHECK(device.queue.enqueueReadBuffer(sums_sq, CL_TRUE, 0, bytes, host_sums_sq.data()));
        double busy = event_seconds(render_done) + event_seconds(reduce_done);
        result.seconds_render += busy;
        report.seconds_busy += busy;
        report.samples += uint64_t(pixels) * n;
        report.batches += 1;
        acc.add_batch(host_sums, host_sums_sq, n_chunks);
        if (progress) progress(begin + n, settings.spp);
    }
    result.devices.push_back(report);
    result.image = acc.image(settings.spp);
    result.nan_samples = acc.nan_samples();
    result.rays = acc.rays();
    return result;
}

}  // namespace mcrt
