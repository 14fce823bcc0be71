// Independent renders of one scene with consecutive seeds, and what the statistical tests read
// off them: the mean of their image means, its standard error from their spread, the variance
// layer's prediction, and any non-finite output. Shared by test_estimators and test_stress.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "render/gpu_scene.h"
#include "render/renderer.h"
#include "render/variants.h"

namespace mcrt::test {

// Settings for a width × height image at spp samples per pixel, every other setting its default.
inline RenderSettings image_settings(int width, int height, uint32_t spp) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.spp = spp;
    return settings;
}

// One estimator of the table of variants with one MIS heuristic (every heuristic for the
// estimators that use one, else the default): the cases the statistical suites run.
struct EstimatorCase {
    const EstimatorVariant* row;
    std::string heuristic;
    bool uses(unsigned bit) const { return (row->uses & bit) != 0; }
    // "mis (power)" for a non-default heuristic, else the estimator's name.
    std::string label() const {
        return std::string(row->name) +
               (heuristic != kMisHeuristicVariants.front().name ? " (" + heuristic + ")" : "");
    }
    // Every light selection for estimators that choose a light; the default for the others.
    std::vector<std::string> selections() const {
        return uses(kUsesLightSelection) ? variant_names(kLightSelectVariants)
                                         : std::vector<std::string>{RenderSettings().light_select};
    }
    void apply(RenderSettings& s) const {
        s.estimator = row->name;
        s.mis_heuristic = heuristic;
    }
};

// Every estimator whose uses include all of `with` and none of `without`.
inline std::vector<EstimatorCase> estimator_cases(unsigned with, unsigned without = 0) {
    std::vector<EstimatorCase> cases;
    for (const EstimatorVariant& row : kEstimatorVariants) {
        if ((row.uses & with) != with || (row.uses & without) != 0) continue;
        if (row.uses & kUsesMisHeuristic)
            for (const std::string& h : variant_names(kMisHeuristicVariants))
                cases.push_back({&row, h});
        else
            cases.push_back({&row, RenderSettings().mis_heuristic});
    }
    return cases;
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
    // Per pixel, averaged over pixels and channels: the variance of a pixel's value across the
    // renders (what the layer should predict), and the layer's value averaged over the renders.
    double pixel_variance_observed = 0, pixel_variance_layer = 0;
    uint64_t nan_samples = 0;
    size_t non_finite_pixels = 0;  // pixels with a NaN or Inf in rgb or variance, over all renders
};

// `count` renders with seeds first_seed, first_seed + 1, ...
inline Renders independent_renders(const DeviceContext& device, const GpuSceneData& data,
                                   RenderSettings settings, int count, uint32_t first_seed) {
    Renders r;
    const size_t n = size_t(settings.width) * settings.height;
    std::vector<double> pixel_sum(3 * n, 0.0), pixel_sum_sq(3 * n, 0.0);
    for (int k = 0; k < count; ++k) {
        settings.seed = first_seed + uint32_t(k);
        RenderResult result = render(device, data, settings);
        for (size_t i = 0; i < 3 * n; ++i) {
            const double v = result.image.rgb[i];
            pixel_sum[i] += v;
            pixel_sum_sq[i] += v * v;
            r.pixel_variance_layer += result.image.variance[i] / double(3 * n * count);
        }
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
    for (size_t i = 0; i < 3 * n; ++i)
        r.pixel_variance_observed +=
            std::max(0.0, pixel_sum_sq[i] - pixel_sum[i] * pixel_sum[i] / count) /
            double(count - 1) / double(3 * n);
    glm::dvec3 var(0.0);
    for (const glm::dvec3& m : r.means) var += (m - r.mean) * (m - r.mean) / double(count - 1);
    r.standard_error = glm::sqrt(var / double(count));
    return r;
}

// |mean − exact| within 4.5 standard errors in every channel, and no non-finite sample. With
// 10 renders the standard error is itself uncertain (χ² with 9 degrees of freedom); 4.5 leaves
// room for that.
inline void check_unbiased(const Renders& r, glm::dvec3 exact, const std::string& what) {
    INFO(what << ": mean (" << r.mean.x << ", " << r.mean.y << ", " << r.mean.z << "), exact ("
              << exact.x << ", " << exact.y << ", " << exact.z << "), standard error ("
              << r.standard_error.x << ", " << r.standard_error.y << ", " << r.standard_error.z
              << ")");
    CHECK(r.nan_samples == 0);
    for (int c = 0; c < 3; ++c) CHECK(std::abs(r.mean[c] - exact[c]) <= 4.5 * r.standard_error[c]);
}

}  // namespace mcrt::test
