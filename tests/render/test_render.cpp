// The render pipeline against analytic images: a polygon light over a diffuse plane (exact
// irradiance from Lambert's formula), emitters seen directly; batching independence.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"
#include "scene_builders.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

RenderResult render_scene(const Scene& scene, const Camera& camera, RenderSettings settings) {
    DeviceContext device = first_device();
    Bvh bvh = build_bvh(scene);
    GpuSceneData data = make_gpu_scene(scene, bvh, camera, settings.width, settings.height);
    return render(device, data, settings);
}

}  // namespace

TEST_CASE("Lambert's formula: a unit square straight above at height 1", "[render][analytic]") {
    // Irradiance from a square of side 2a at height h centred above x, L = 1:
    // E = 4 · (a/√(a²+h²)) · atan(a/√(a²+h²)) (PBRT 3rd ed. ex. / Howell's catalogue C-11).
    double a = 0.5, h = 1.0, s = a / std::sqrt(a * a + h * h);
    double expected = 4.0 * s * std::atan(s);
    double E = lambert_irradiance({{-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}}, {0, 0, 0},
                                  {0, 1, 0}, 1.0);
    CHECK(E == Approx(expected).epsilon(1e-12));
}

TEST_CASE("light-area is unbiased on a polygon light over a plane (Lambert's formula)",
          "[render][analytic]") {
    PlaneScene ps;
    RenderSettings settings;
    // Enough samples for a standard error under 0.5% of the mean: a 2% bias fails.
    settings.width = 32;
    settings.height = 32;
    settings.spp = 256;
    settings.seed = 3;
    std::vector<double> exact = ps.exact_image(settings.width, settings.height);
    for (const char* select : {"uniform", "power"}) {
        settings.light_select = select;
        RenderResult r = render_scene(ps.scene, ps.camera, settings);
        REQUIRE(r.nan_samples == 0);
        const size_t n = size_t(settings.width) * settings.height;
        int outliers = 0;
        for (int c = 0; c < 3; ++c) {
            // Image mean against the exact mean, within 4.5 standard errors of the estimate;
            // the standard error from the per-pixel variance of the mean (pixels independent).
            double sum = 0, sum_exact = 0, var_sum = 0;
            for (size_t p = 0; p < n; ++p) {
                double v = r.image.rgb[3 * p + c], e = exact[3 * p + c],
                       var = r.image.variance[3 * p + c];
                sum += v;
                sum_exact += e;
                var_sum += var;
                if (std::abs(v - e) > 4.5 * std::sqrt(var)) ++outliers;
            }
            double se = std::sqrt(var_sum) / n;
            INFO("light select " << select << ", channel " << c << ": mean " << sum / n
                                 << ", exact " << sum_exact / n << ", standard error " << se);
            CHECK(se > 0);
            CHECK(std::abs(sum - sum_exact) / n < 4.5 * se);
            // The test has the power to see a bias of a percent or two.
            CHECK(se < 0.005 * sum_exact / n);
        }
        // Each pixel within 4.5 of its own standard errors, but for the odd heavy tail.
        CHECK(outliers <= 3);
    }
}

TEST_CASE("power selection has lower variance than uniform when light powers differ",
          "[render][analytic]") {
    PlaneScene ps;
    RenderSettings settings = image_settings(16, 16, 64);
    double var_sum[2] = {0, 0};
    for (int power = 0; power < 2; ++power) {
        settings.light_select = power ? "power" : "uniform";
        RenderResult r = render_scene(ps.scene, ps.camera, settings);
        for (float v : r.image.variance) var_sum[power] += v;
    }
    INFO("summed variance: uniform " << var_sum[0] << ", power " << var_sum[1]);
    CHECK(var_sum[1] < var_sum[0]);
}

TEST_CASE("an emitter seen directly shows Le on its emitting faces only", "[render]") {
    RenderSettings settings = image_settings(8, 8, 16);
    const glm::vec3 Le(2.0f, 3.0f, 4.0f);
    for (bool double_sided : {false, true})
        for (bool from_front : {true, false}) {
            Scene scene;
            // A black emitter filling the view: nothing to reflect, so the pixel is exactly Le.
            uint32_t m = add_material(scene, glm::vec3(0.0f), Le, double_sided);
            float y = 0.0f;
            if (from_front)  // faces +Y, toward the camera above
                add_quad(scene, {-5, y, -5}, {-5, y, 5}, {5, y, 5}, {5, y, -5}, m);
            else
                add_quad(scene, {-5, y, -5}, {5, y, -5}, {5, y, 5}, {-5, y, 5}, m);
            RenderResult r = render_scene(scene, looking_down({0, 2, 0}, 0.5f), settings);
            glm::vec3 expected = (from_front || double_sided) ? Le : glm::vec3(0.0f);
            for (size_t p = 0; p < r.image.rgb.size() / 3; ++p)
                for (int c = 0; c < 3; ++c) {
                    INFO("double sided " << double_sided << ", from front " << from_front);
                    REQUIRE(r.image.rgb[3 * p + c] == Approx(expected[c]).epsilon(1e-6));
                    REQUIRE(r.image.variance[3 * p + c] == Approx(0.0).margin(1e-9));
                }
        }
}

TEST_CASE("the image is bitwise identical for any batch size, and changes with the seed",
          "[render][determinism]") {
    PlaneScene ps;
    RenderSettings settings;
    settings.width = 16;
    settings.height = 12;
    settings.spp = 40;  // not a multiple of the chunk: the last chunk is short
    // Replicates included: each chunk holds 16 / K samples of each of the K replicates.
    auto [sampler, replicates] =
        GENERATE(std::make_pair("independent", 1u), std::make_pair("sobol", 4u),
                 std::make_pair("stratified", 8u));
    settings.sampler = sampler;
    settings.replicates = replicates;
    INFO(sampler << ", " << replicates << " replicate(s)");
    settings.batch = 16;
    RenderResult a = render_scene(ps.scene, ps.camera, settings);
    settings.batch = 48;
    RenderResult b = render_scene(ps.scene, ps.camera, settings);
    settings.batch = 1;  // rounded up to one chunk
    RenderResult c = render_scene(ps.scene, ps.camera, settings);
    REQUIRE(a.devices[0].batches == 3);
    REQUIRE(b.devices[0].batches == 1);
    auto same_bits = [](const std::vector<float>& x, const std::vector<float>& y) {
        return x.size() == y.size() &&
               std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
    };
    CHECK(same_bits(a.image.rgb, b.image.rgb));
    CHECK(same_bits(a.image.variance, b.image.variance));
    CHECK(same_bits(a.image.rgb, c.image.rgb));
    CHECK(a.rays == b.rays);
    settings.seed = 1;
    RenderResult d = render_scene(ps.scene, ps.camera, settings);
    CHECK(!same_bits(a.image.rgb, d.image.rgb));
}

TEST_CASE("a scene without lights renders black without error", "[render]") {
    Scene scene;
    add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3},
             add_material(scene, glm::vec3(0.8f)));
    RenderSettings settings = image_settings(8, 8, 4);
    RenderResult r = render_scene(scene, looking_down({0, 2, 0}, 0.5f), settings);
    for (float v : r.image.rgb) CHECK(v == 0.0f);
    CHECK(r.nan_samples == 0);
    CHECK(r.rays == 8u * 8u * 4u);  // camera rays only
}

TEST_CASE("batch sizes are whole chunks and never exceed the samples asked for", "[render]") {
    CHECK(batch_samples_per_pixel(1, 512, 512, 16) == 16);
    CHECK(batch_samples_per_pixel(17, 512, 512, 1024) == 32);
    CHECK(batch_samples_per_pixel(0, 512, 512, 1024) == 16);  // 2^22 samples per launch
    CHECK(batch_samples_per_pixel(0, 64, 64, 1024) == 1024);
    CHECK(batch_samples_per_pixel(0, 64, 64, 20) == 32);  // covers spp in one launch
    CHECK(batch_samples_per_pixel(0, 16384, 16384, 4) == 16);
}

TEST_CASE("an emitter of 1e30 renders a finite image and variance layer", "[render][variance]") {
    // Float sums of squares overflowed at radiance 4.6e18 before the device shifted and scaled
    // them: a pixel of constant 1e30 then showed an infinite variance.
    Scene scene;
    uint32_t floor = add_material(scene, glm::vec3(0.5f));
    add_quad(scene, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, floor);
    uint32_t light = add_material(scene, glm::vec3(0.0f), glm::vec3(1e30f));
    // Facing +Y, seen from above, covering the middle of the view.
    add_quad(scene, {-0.3f, 0.5f, -0.3f}, {-0.3f, 0.5f, 0.3f}, {0.3f, 0.5f, 0.3f},
             {0.3f, 0.5f, -0.3f}, light);
    Camera camera = looking_down(glm::vec3(0.0f, 3.0f, 0.0f), glm::radians(60.0f));
    RenderSettings settings = image_settings(16, 16, 32);
    for (const char* estimator : {"light-area", "hemisphere-cosine"}) {
        settings.estimator = estimator;
        RenderResult r = render_scene(scene, camera, settings);
        INFO(estimator << ": " << r.variance_clamped << " variance values clamped to FLT_MAX");
        size_t light_pixels = 0;
        for (size_t i = 0; i < r.image.rgb.size(); ++i) {
            REQUIRE(std::isfinite(r.image.rgb[i]));
            REQUIRE(std::isfinite(r.image.variance[i]));
            // A pixel wholly on the emitter: every sample exactly 1e30, no spread at all.
            if (r.image.rgb[i] == 1e30f) {
                CHECK(r.image.variance[i] == 0.0f);
                ++light_pixels;
            }
        }
        CHECK(light_pixels > 0);
        CHECK(r.nan_samples == 0);
    }
}
