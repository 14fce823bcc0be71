// Independent renders of one scene with consecutive seeds, and what the statistical tests read
// off them: the mean of their image means, its standard error from their spread, the variance
// layer's prediction, and any non-finite output. Shared by test_estimators and test_stress.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/gpu_scene.h"
#include "render/renderer.h"

namespace mcrt::test {

inline const char* sampler_name(SamplerKind s) {
    return s == SamplerKind::Independent ? "independent"
           : s == SamplerKind::Stratified ? "stratified"
                                          : "sobol";
}

inline const char* select_name(LightSelect s) {
    return s == LightSelect::Uniform ? "uniform" : s == LightSelect::Power ? "power" : "alias";
}

// The scene's BVH and device arrays for a render of `settings`' size seen from `camera`.
inline GpuSceneData gpu_scene_for(const Scene& scene, const Camera& camera,
                                  const RenderSettings& settings) {
    return make_gpu_scene(scene, build_bvh(scene), camera, settings.width, settings.height);
}

struct Renders {
    std::vector<glm::dvec3> means;  // image mean of each independent render
    glm::dvec3 mean{0.0}, standard_error{0.0};
    double mean_layer_variance = 0;  // mean over renders of the variance layer's image mean
    uint64_t nan_samples = 0;
    size_t non_finite_pixels = 0;  // pixels with a NaN or Inf in rgb or variance, over all renders
};

// `count` renders with seeds first_seed, first_seed + 1, ...
inline Renders independent_renders(const DeviceContext& device, const GpuSceneData& data,
                                   RenderSettings settings, int count, uint32_t first_seed) {
    Renders r;
    const size_t n = size_t(settings.width) * settings.height;
    for (int k = 0; k < count; ++k) {
        settings.seed = first_seed + uint32_t(k);
        RenderResult result = render(device, data, settings);
        glm::dvec3 m(0.0);
        double layer = 0;
        for (size_t p = 0; p < n; ++p) {
            bool finite = true;
            for (int c = 0; c < 3; ++c) {
                finite = finite && std::isfinite(result.image.rgb[3 * p + c]) &&
                         std::isfinite(result.image.variance[3 * p + c]);
                m[c] += result.image.rgb[3 * p + c] / double(n);
                layer += result.image.variance[3 * p + c] / double(3 * n * n);
            }
            r.non_finite_pixels += finite ? 0 : 1;
        }
        r.means.push_back(m);
        r.mean += m / double(count);
        r.mean_layer_variance += layer / count;
        r.nan_samples += result.nan_samples;
    }
    glm::dvec3 var(0.0);
    for (const glm::dvec3& m : r.means) var += (m - r.mean) * (m - r.mean) / double(count - 1);
    r.standard_error = glm::sqrt(var / double(count));
    return r;
}

}  // namespace mcrt::test
