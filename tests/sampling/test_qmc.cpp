// Quasi-Monte Carlo that keeps its stratification: a light of two triangles gets its triangle and
// the point on it from one Sobol sample (the selection number remapped into the point), so the
// error of light-area with Sobol samples keeps falling faster than 1/spp, as for a one-triangle
// light. Errors measured from independent renders (the variance of a pixel across seeds).
#include <catch2/catch.hpp>
#include <cmath>

#include "analytic_scenes.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

// A floor under a square light 1 above it, seen from above: no occluders, a smooth integrand.
// `triangles` 2: the light as a quad of two triangles; 1: one triangle of the same area.
struct LightOverFloor {
    Scene scene;
    Camera camera = looking_down(glm::vec3(0.9f, 2.0f, 0.1f), glm::radians(15.0f));
    explicit LightOverFloor(int triangles) {
        uint32_t floor = add_material(scene, glm::vec3(0.5f));
        add_quad(scene, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, floor);
        uint32_t light = add_material(scene, glm::vec3(0.0f), glm::vec3(10.0f));
        if (triangles == 2)  // facing −Y: counter-clockwise seen from below
            add_quad(scene, {-0.3f, 1, -0.3f}, {0.3f, 1, -0.3f}, {0.3f, 1, 0.3f}, {-0.3f, 1, 0.3f},
                     light);
        else
            add_triangle(scene, {-0.3f, 1, -0.3f}, {0.9f, 1, -0.3f}, {-0.3f, 1, 0.9f}, light);
    }
};

// Mean over pixels and channels of the variance of a pixel across `seeds` independent renders.
double pixel_variance(const DeviceContext& device, const GpuSceneData& data, RenderSettings s,
                      int seeds) {
    const size_t n = 3 * size_t(s.width) * s.height;
    std::vector<double> sum(n, 0.0), sum_sq(n, 0.0);
    for (int k = 0; k < seeds; ++k) {
        s.seed = 500 + uint32_t(k);
        RenderResult r = render(device, data, s);
        for (size_t i = 0; i < n; ++i) {
            sum[i] += r.image.rgb[i];
            sum_sq[i] += double(r.image.rgb[i]) * r.image.rgb[i];
        }
    }
    double v = 0;
    for (size_t i = 0; i < n; ++i)
        v += (sum_sq[i] - sum[i] * sum[i] / seeds) / (seeds - 1) / double(n);
    return v;
}

}  // namespace

TEST_CASE("Sobol's variance x spp keeps falling on a light made of two triangles",
          "[qmc][sampling]") {
    DeviceContext device = first_device();
    RenderSettings settings;
    // Pixels small enough that the pixel footprint's share of the error is small against the
    // light's (the jitter and light pairs are stratified each, not jointly).
    settings.width = 32;
    settings.height = 32;
    settings.estimator = "light-area";
    settings.sampler = "sobol";
    for (const std::string& select : variant_names(kLightSelectVariants)) {
        settings.light_select = select;
        double fall[2];
        for (int triangles : {2, 1}) {
            LightOverFloor scene(triangles);
            GpuSceneData data = gpu_scene_for(scene.scene, scene.camera, settings);
            REQUIRE(data.lights.size() == size_t(triangles));
            settings.spp = 16;
            double v16 = pixel_variance(device, data, settings, 16) * 16;
            settings.spp = 256;
            double v256 = pixel_variance(device, data, settings, 16) * 256;
            fall[triangles - 1] = v16 / v256;
            INFO(select << ", " << triangles << " triangle(s): variance x spp " << v16
                        << " at 16 spp, " << v256 << " at 256 spp: falls " << v16 / v256 << "x");
            CHECK(v16 / v256 >= 2.0);
            WARN(select << ", " << triangles << " triangle(s): variance x spp falls " << v16 / v256
                        << "x from 16 to 256 spp (" << v16 << " -> " << v256 << ")");
        }
        (void)fall;
    }
}
