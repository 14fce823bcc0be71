// Rendering a scene on a device: batching, the render and reduction kernels, accumulation.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cl/device.h"
#include "image/image.h"
#include "render/gpu_scene.h"

namespace mcrt {

enum class SamplerKind { Independent, Stratified, Sobol };
enum class MisHeuristic { Balance, Power };

struct RenderSettings {
    int width = 512, height = 512;
    uint32_t spp = 16;
    std::string estimator = "light-area";  // a name of kEstimators
    LightSelect light_select = LightSelect::Power;
    SamplerKind sampler = SamplerKind::Independent;
    MisHeuristic mis_heuristic = MisHeuristic::Balance;
    glm::vec3 sky{1.0f};        // ambient estimators: uniform sky radiance
    float ao_distance = 0.0f;   // ambient estimators: occlusion range, 0 = unbounded
    uint32_t seed = 0;
    uint32_t batch = 0;  // samples per pixel per launch; 0 chooses; rounded up to whole chunks
};

// The estimators of DESIGN.md, by their command-line names.
extern const std::vector<std::string> kEstimators;

struct DeviceReport {
    std::string name;
    uint64_t samples = 0;
    uint64_t batches = 0;
    double seconds_busy = 0;  // kernel time from profiling events
};

struct RenderResult {
    Image image;
    uint64_t nan_samples = 0;  // non-finite samples, left out of the image
    uint64_t rays = 0;         // camera and shadow rays traced
    double seconds_render = 0; // kernel time (profiling events)
    double seconds_build = 0;  // kernel compilation
    std::vector<DeviceReport> devices;
};

// Progress: samples per pixel done so far, of the total.
using ProgressSink = std::function<void(uint32_t done, uint32_t total)>;

// Accumulates per-chunk sums in double precision, in the order they are added; callers add
// batches in sample-index order, so the result does not depend on how samples were batched.
class Accumulator {
public:
    Accumulator(int width, int height);
    // sums / sums_sq: pixels × chunks float4 as reduce_chunks writes them.
    void add_batch(const std::vector<gpu::float4>& sums, const std::vector<gpu::float4>& sums_sq,
                   uint32_t chunks);
    Image image(uint32_t spp) const;
    uint64_t nan_samples() const { return nan_samples_; }
    uint64_t rays() const { return rays_; }

private:
    int width_, height_;
    std::vector<double> sum_, sum_sq_;  // 3 per pixel
    uint64_t nan_samples_ = 0, rays_ = 0;
};

// The -D options of the render program for these settings (throws InputError for an unknown
// estimator).
std::string render_program_options(const RenderSettings& settings);

// Renders on one device. Throws InputError for settings it cannot honour, RuntimeError /
// ClError for device failures.
RenderResult render(const DeviceContext& device, const GpuSceneData& scene,
                    const RenderSettings& settings, const ProgressSink& progress = {});

// Samples per pixel per launch: `requested` rounded up to whole chunks, or, when 0, about
// 2^22 samples per launch.
uint32_t batch_samples_per_pixel(uint32_t requested, int width, int height, uint32_t spp);

}  // namespace mcrt
