// Path tracing (--max-depth > 1): every direct estimator as next-event estimation at each vertex,
// checked against scenes whose every depth is known exactly — a closed furnace, where a path of N
// reflections sees L_e(1 − ρ^(N+1))/(1 − ρ), and an open floor under a uniform sky, which sees only
// the sky at every depth — and bit for bit across batch sizes and devices at depth 8.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

constexpr int kRenders = 10;
constexpr uint32_t kFirstSeed = 2000;

// Within the renders' error bars, or equal up to float rounding where a strategy has no variance
// (the cosine and BSDF estimators in a Lambertian furnace or under a uniform sky).
void check_close(const Renders& r, glm::dvec3 exact, const std::string& what) {
    INFO(what << ": mean (" << r.mean.x << ", " << r.mean.y << ", " << r.mean.z << "), exact ("
              << exact.x << ", " << exact.y << ", " << exact.z << "), standard error ("
              << r.standard_error.x << ", " << r.standard_error.y << ", " << r.standard_error.z
              << ")");
    CHECK(r.nan_samples == 0);
    for (int c = 0; c < 3; ++c)
        CHECK(std::abs(r.mean[c] - exact[c]) <= 4.5 * r.standard_error[c] + 2e-5 * exact[c]);
}

// The estimators checked on the furnace, and those that see the sky light.
std::vector<EstimatorCase> path_cases(std::initializer_list<const char*> names) {
    std::vector<EstimatorCase> cases;
    for (const EstimatorCase& c : estimator_cases(kUsesLights | kUsesSkyLight))
        for (const char* n : names)
            if (std::string(c.row->name) == n && c.heuristic == RenderSettings().mis_heuristic)
                cases.push_back(c);
    return cases;
}

}  // namespace

TEST_CASE("a closed furnace renders Le (1 - rho^(N+1)) / (1 - rho) at depth N",
          "[paths][analytic]") {
    // A sphere emitting Le inward and reflecting ρ around the camera: after k reflections every
    // path still sees Le, so depth N sums Le ρ^k for k = 0 .. N.
    DeviceContext device = first_device();
    const FurnaceScene furnace;
    const Scene& scene = furnace.scene;
    const glm::vec3 Le = furnace.Le, albedo = furnace.albedo;
    const Camera& camera = furnace.camera;
    RenderSettings settings = image_settings(8, 8, 32);
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    struct Depth {
        uint32_t max_depth, rr_depth;
    };
    // 64 with roulette from the third reflection on; 2 and 5 without any.
    const std::vector<Depth> depths = {{2, 1024}, {5, 1024}, {64, 3}};
    const std::vector<EstimatorCase> cases =
        path_cases({"mis", "light-area", "hemisphere-cosine", "bsdf", "light-solid-angle"});
    REQUIRE(cases.size() == 5);
    for (const Depth& d : depths) {
        glm::dvec3 exact = glm::dvec3(Le) *
                           (1.0 - glm::pow(glm::dvec3(albedo), glm::dvec3(d.max_depth + 1.0))) /
                           (1.0 - glm::dvec3(albedo));
        for (const EstimatorCase& v : cases)
            for (const char* sampler : {"independent", "stratified", "sobol"}) {
                v.apply(settings);
                settings.sampler = sampler;
                settings.replicates = resolve_replicates(0, settings);
                settings.max_depth = d.max_depth;
                settings.rr_depth = d.rr_depth;
                Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
                check_close(r, exact,
                            v.label() + " / " + sampler + " at depth " +
                                std::to_string(d.max_depth) + ", roulette from " +
                                std::to_string(d.rr_depth));
            }
    }
}

TEST_CASE("roulette ends paths and leaves the furnace unbiased; its stats count them", "[paths]") {
    DeviceContext device = first_device();
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.5f), glm::vec3(1.0f));
    add_sphere(scene, glm::vec3(0.0f), 1.0f, 16, 8, m, /*inward=*/true);
    Camera camera = looking_down(glm::vec3(0.0f), glm::radians(60.0f));
    RenderSettings settings = image_settings(8, 8, 64);
    settings.estimator = "light-area";
    settings.max_depth = 1024;
    settings.rr_depth = 1;
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    RenderResult result = render(device, data, settings);
    const double samples = 8.0 * 8.0 * 64.0;
    // Survival 1/2 (the throughput) at every reflection from the first: 2 vertices on average
    // (the camera's hit, then a geometric number of further ones).
    INFO("vertices " << result.path_vertices << ", roulette " << result.roulette_ends);
    CHECK(result.roulette_ends == uint64_t(samples));
    CHECK(result.path_vertices / samples == Approx(2.0).epsilon(0.05));
    // A camera ray, then one continuation per further vertex, and the shadow rays.
    CHECK(result.rays > result.path_vertices);
    // Depth 1 takes no roulette and one vertex per sample.
    settings.max_depth = 1;
    RenderResult direct = render(device, data, settings);
    CHECK(direct.roulette_ends == 0);
    CHECK(direct.path_vertices == uint64_t(samples));
}

TEST_CASE("an open floor under a uniform sky renders albedo x L_sky at every depth",
          "[paths][analytic]") {
    // The floor sees only the sky: every path that leaves it escapes. A light below the floor,
    // facing down, puts the sky beside an area light (half the light samples each) without
    // lighting the floor.
    DeviceContext device = first_device();
    const glm::dvec3 albedo(0.7, 0.5, 0.3), sky(1.0, 2.0, 0.5);
    Camera camera = looking_down(glm::vec3(0, 3, 0), glm::radians(40.0f));
    RenderSettings settings = image_settings(8, 8, 32);
    settings.sky = glm::vec3(sky);
    settings.sky_light = true;
    const std::vector<EstimatorCase> cases = estimator_cases(kUsesSkyLight);
    REQUIRE(cases.size() >= 6);
    for (bool hidden_light : {false, true}) {
        Scene scene = floor_scene(albedo, hidden_light);
        GpuSceneData data = gpu_scene_for(scene, camera, settings);
        for (uint32_t depth : {1u, 2u, 8u})
            for (const EstimatorCase& v : cases) {
                v.apply(settings);
                settings.max_depth = depth;
                settings.light_select = "power";
                Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
                check_close(r, albedo * sky,
                            v.label() + " at depth " + std::to_string(depth) +
                                (hidden_light ? ", beside an area light" : ", the sky alone"));
            }
    }
}

TEST_CASE("without --sky a direct estimator's escaping rays see black", "[paths]") {
    DeviceContext device = first_device();
    Scene scene;
    add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3},
             add_material(scene, glm::vec3(0.5f)));
    Camera camera = looking_down(glm::vec3(0, 3, 0), glm::radians(120.0f));  // sees past the floor
    RenderSettings settings = image_settings(8, 8, 16);
    settings.sky = glm::vec3(3.0f);  // radiance given, but no sky light
    settings.max_depth = 4;
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    for (const EstimatorCase& v : estimator_cases(kUsesSkyLight)) {
        v.apply(settings);
        RenderResult result = render(device, data, settings);
        double sum = 0;
        for (float x : result.image.rgb) sum += x;
        INFO(v.label());
        CHECK(sum == 0.0);
    }
}

TEST_CASE("the variance layer predicts the spread of path-traced renders for every sampler",
          "[paths][variance]") {
    // The furnace with roulette from the 2nd reflection: per pixel, averaged over the pixels and
    // channels, the layer against the variance of each pixel across 16 renders, within 35% (as
    // the direct-lighting test in test_estimators.cpp); replicates for the correlated samplers.
    DeviceContext device = first_device();
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.7f, 0.5f, 0.3f), glm::vec3(1.0f));
    add_sphere(scene, glm::vec3(0.0f), 1.0f, 16, 8, m, /*inward=*/true);
    RenderSettings settings = image_settings(8, 8, 32);
    settings.max_depth = 64;
    settings.rr_depth = 2;
    GpuSceneData data = gpu_scene_for(
        scene, looking_down(glm::vec3(0.1f, 0.0f, 0.2f), glm::radians(90.0f)), settings);
    for (const EstimatorCase& v : path_cases({"mis", "light-area"}))
        for (const std::string& sampler : variant_names(kSamplerVariants)) {
            v.apply(settings);
            settings.sampler = sampler;
            settings.replicates = resolve_replicates(0, settings);
            Renders r = independent_renders(device, data, settings, 16, kFirstSeed);
            INFO(v.label() << " / " << sampler << ", " << settings.replicates
                           << " replicate(s): layer " << r.pixel_variance_layer << ", observed "
                           << r.pixel_variance_observed);
            REQUIRE(r.pixel_variance_observed > 0);
            CHECK(r.pixel_variance_layer == Approx(r.pixel_variance_observed).epsilon(0.35));
            CHECK(r.non_finite_pixels == 0);
        }
}
