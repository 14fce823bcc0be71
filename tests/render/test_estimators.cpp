// Every estimator × light selection × sampler against exact images: a polygon light over a
// plane (Lambert's formula), a furnace (an emitting, reflecting sphere around the camera), and
// ambient light next to a wall (the wall's projected solid angle). Standard errors come from
// independent renders, so they hold for stratified and Sobol samplers too.
#include <catch2/catch.hpp>
#include <cmath>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

constexpr int kRenders = 10;
constexpr uint32_t kFirstSeed = 1000;  // renders use seeds 1000, 1001, ...

}  // namespace

TEST_CASE("direct-light estimators are unbiased on a polygon light over a plane",
          "[estimators][analytic]") {
    DeviceContext device = first_device();
    PlaneScene ps;
    RenderSettings settings = image_settings(16, 16, 64);
    GpuSceneData data = gpu_scene_for(ps.scene, ps.camera, settings);
    glm::dvec3 exact = image_mean(ps.exact_image(settings.width, settings.height));

    // Every direct estimator of the table: those that use lights and not the sky.
    const std::vector<EstimatorCase> cases = estimator_cases(kUsesLights, kUsesSky);
    REQUIRE(cases.size() >= 6);
    for (const EstimatorCase& v : cases)
        for (const std::string& select : v.selections()) {
            bool selects = v.uses(kUsesLightSelection);
            for (const std::string& sampler : variant_names(kSamplerVariants)) {
                v.apply(settings);
                settings.light_select = select;
                settings.sampler = sampler;
                // Hemisphere sampling rarely finds these small lights: give it more samples.
                settings.spp = selects ? 64 : 1024;
                Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
                std::string what = v.label() + " / " + select + " / " + sampler;
                check_unbiased(r, exact, what);
                // Not vacuous: the error bar is a few percent of the value at most.
                CHECK(r.standard_error.x < 0.05 * exact.x);
            }
        }
}

TEST_CASE("in a furnace every estimator is unbiased and the cosine estimator has zero variance",
          "[estimators][analytic]") {
    // A sphere emitting Le inward and reflecting with albedo ρ around the camera: every point
    // sees Le in all directions, so a pixel is Le + ρ·Le exactly.
    DeviceContext device = first_device();
    const FurnaceScene furnace;
    const Scene& scene = furnace.scene;
    const glm::vec3 Le = furnace.Le, albedo = furnace.albedo;
    const Camera& camera = furnace.camera;
    RenderSettings settings = image_settings(8, 8, 32);
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    glm::dvec3 exact = glm::dvec3(Le) * (1.0 + glm::dvec3(albedo));
    for (const EstimatorCase& v : estimator_cases(kUsesLights, kUsesSky | kUsesMisHeuristic)) {
        const std::string estimator = v.row->name;
        v.apply(settings);
        Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
        if (estimator == "hemisphere-cosine" || estimator == "bsdf") {
            // f·Le·cosθ / (cosθ/π) = ρ·Le for every sample: only rounding is left (the BSDF's
            // own density is cosθ/π on this Lambertian sphere).
            INFO("cosine: mean " << r.mean.x << ", layer variance " << r.mean_layer_variance);
            for (int c = 0; c < 3; ++c) CHECK(r.mean[c] == Approx(exact[c]).epsilon(1e-5));
            // Zero variance, reported as such: the device sums samples shifted by the first of
            // their run, so equal values cancel exactly, and what is left is the estimate's own
            // float rounding (cosθ / (cosθ/π) is π to an ulp), far below 1e-10 of the mean².
            double mean_value = (r.mean.x + r.mean.y + r.mean.z) / 3.0;
            CHECK(r.mean_layer_variance * settings.spp < 1e-10 * mean_value * mean_value);
        } else {
            check_unbiased(r, exact, estimator);
            CHECK(r.mean_layer_variance > 0.0);
        }
    }
}

TEST_CASE("ambient estimators are unbiased next to a wall (its projected solid angle)",
          "[estimators][analytic]") {
    // Floor y = 0 and a wall x = 0 of height 1 and width 3; the camera sees only floor. At a
    // floor point the unoccluded fraction of (1/π)∫cosθ dω is 1 − F, F = the wall's form factor
    // = Lambert's irradiance from the wall polygon with L = 1, over π.
    DeviceContext device = first_device();
    Scene scene;
    const glm::dvec3 albedo(0.7, 0.6, 0.5), sky(1.0, 2.0, 0.5);
    uint32_t floor = add_material(scene, glm::vec3(albedo));
    uint32_t wall = add_material(scene, glm::vec3(0.3f));
    add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
    std::vector<glm::dvec3> wall_polygon = {{0, 0, -1.5}, {0, 1, -1.5}, {0, 1, 1.5}, {0, 0, 1.5}};
    add_quad(scene, wall_polygon[0], wall_polygon[1], wall_polygon[2], wall_polygon[3], wall);
    Camera camera = looking_down(glm::vec3(0.7f, 3.0f, 0.0f), 2.0f * std::atan(0.5f / 3.0f));
    RenderSettings settings = image_settings(16, 16, 64);
    settings.sky = glm::vec3(sky);
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    glm::dvec3 exact = image_mean(exact_plane_image(camera, 16, 16, [&](glm::dvec3 p) {
        double form_factor = lambert_irradiance(wall_polygon, p, {0, 1, 0}, 1.0) / M_PI;
        return albedo * sky * (1.0 - form_factor);
    }));
    const std::vector<EstimatorCase> cases = estimator_cases(kUsesSky);
    REQUIRE(cases.size() >= 3);
    for (const EstimatorCase& v : cases)
        for (const std::string& sampler : variant_names(kSamplerVariants)) {
            v.apply(settings);
            settings.sampler = sampler;
            Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
            check_unbiased(r, exact, v.label() + " / " + sampler);
            CHECK(r.standard_error.x < 0.02 * exact.x);
        }
}

TEST_CASE("ambient occlusion distance: a far wall stops occluding", "[estimators]") {
    DeviceContext device = first_device();
    Scene scene;
    uint32_t floor = add_material(scene, glm::vec3(1.0f));
    add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
    add_quad(scene, {0, 0, -1.5}, {0, 1, -1.5}, {0, 1, 1.5}, {0, 0, 1.5}, floor);
    Camera camera = looking_down(glm::vec3(0.7f, 3.0f, 0.0f), 0.2f);
    RenderSettings settings = image_settings(4, 4, 64);
    settings.estimator = "ambient-cosine";
    settings.ao_distance = 0.1f;  // the wall is 0.6 or more away: nothing occludes
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    RenderResult r = render(device, data, settings);
    for (float v : r.image.rgb) CHECK(v == Approx(1.0f).epsilon(1e-6));
}

TEST_CASE("power and alias selection have lower variance than uniform with unequal lights",
          "[estimators]") {
    DeviceContext device = first_device();
    PlaneScene ps;
    RenderSettings settings = image_settings(16, 16, 64);
    GpuSceneData data = gpu_scene_for(ps.scene, ps.camera, settings);
    double layer[3];
    const char* selections[3] = {"uniform", "power", "alias"};
    for (int k = 0; k < 3; ++k) {
        settings.light_select = selections[k];
        layer[k] = independent_renders(device, data, settings, 4, kFirstSeed).mean_layer_variance;
    }
    INFO("variance: uniform " << layer[0] << ", power " << layer[1] << ", alias " << layer[2]);
    CHECK(layer[1] < layer[0]);
    CHECK(layer[2] < layer[0]);
    // The same distribution: within the noise of the variance estimates.
    CHECK(layer[2] == Approx(layer[1]).epsilon(0.1));
}

TEST_CASE("with the independent sampler the variance layer predicts the spread of renders",
          "[estimators]") {
    DeviceContext device = first_device();
    PlaneScene ps;
    RenderSettings settings = image_settings(16, 16, 32);
    GpuSceneData data = gpu_scene_for(ps.scene, ps.camera, settings);
    const int renders = 40;
    Renders r = independent_renders(device, data, settings, renders, kFirstSeed);
    // Variance of the image mean predicted by the layer, against the spread of 40 renders; the
    // spread's own relative uncertainty is √(2/39) ≈ 23%, so 35% is about 1.5 of its σ.
    double predicted = r.mean_layer_variance;
    double observed = 0;
    for (int c = 0; c < 3; ++c)
        observed += r.standard_error[c] * r.standard_error[c] * renders / 3.0;
    INFO("predicted " << predicted << ", observed " << observed);
    CHECK(observed == Approx(predicted).epsilon(0.35));
}

TEST_CASE("the variance layer predicts the spread of renders for every estimator and sampler",
          "[estimators][variance]") {
    // With correlated samples (stratified, Sobol, the Fibonacci spiral) the layer is the spread
    // of independent replicate means (resolve_replicates' default); with independent ones the
    // samples' own variance. Per pixel, averaged over the 256 pixels and 3 channels, against the
    // variance of each pixel across 16 independent renders: within 35%.
    DeviceContext device = first_device();
    PlaneScene ps;
    RenderSettings settings = image_settings(16, 16, 64);
    GpuSceneData plane = gpu_scene_for(ps.scene, ps.camera, settings);
    // Ambient light next to a wall, as the ambient test: the sky estimators' scene.
    Scene ambient;
    uint32_t floor = add_material(ambient, glm::vec3(0.5f));
    add_quad(ambient, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
    add_quad(ambient, {0, 0, -1.5}, {0, 1, -1.5}, {0, 1, 1.5}, {0, 0, 1.5}, floor);
    GpuSceneData wall =
        gpu_scene_for(ambient, looking_down(glm::vec3(0.7f, 3.0f, 0.0f), 0.6f), settings);
    for (const EstimatorCase& v : estimator_cases(0))
        for (const std::string& sampler : variant_names(kSamplerVariants)) {
            v.apply(settings);
            settings.sampler = sampler;
            settings.replicates = resolve_replicates(0, settings);
            Renders r = independent_renders(device, v.uses(kUsesSky) ? wall : plane, settings, 16,
                                            kFirstSeed);
            INFO(v.label() << " / " << sampler << ", " << settings.replicates
                           << " replicate(s): layer " << r.pixel_variance_layer << ", observed "
                           << r.pixel_variance_observed);
            REQUIRE(r.pixel_variance_observed > 0);
            CHECK(r.pixel_variance_layer == Approx(r.pixel_variance_observed).epsilon(0.35));
            CHECK(r.non_finite_pixels == 0);
        }
}
