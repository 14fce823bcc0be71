// KHR_lights_punctual lights drawn: point and spot lights over a Lambertian floor give
// albedo/π · I cosθ/d² · falloff, a directional light albedo/π · E cosθ and a black shadow, every
// light selection the same image beside area lights; the direction estimators cannot see them
// (a black image and one warning); two devices and MPI ranks render the same bytes.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "image/image.h"
#include "independent_renders.h"
#include "process_support.h"
#include "render/renderer.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

// Two PoCL devices on the same cores (before PoCL initialises); the first is the one device of
// the statistical tests.
const bool two_devices = [] {
    setenv("POCL_DEVICES", "pthread basic", 1);
    unsetenv("MCRT_FAULT_INJECT");
    return true;
}();

constexpr int kRenders = 12;
constexpr int kPixelRenders = 40;  // per-pixel standard errors: their own spread is small
constexpr uint32_t kFirstSeed = 3000;

PunctualLight point_light(glm::vec3 position, glm::vec3 intensity) {
    PunctualLight l;
    l.type = PunctualType::Point;
    l.position = position;
    l.intensity = intensity;
    return l;
}

// A spot at `position` pointing along `direction`, its falloff the extension's.
PunctualLight spot_light(glm::vec3 position, glm::vec3 direction, glm::vec3 intensity,
                         double inner_degrees, double outer_degrees) {
    PunctualLight l;
    l.type = PunctualType::Spot;
    l.position = position;
    l.direction = glm::normalize(direction);
    l.intensity = intensity;
    l.cos_inner = float(std::cos(glm::radians(inner_degrees)));
    l.cos_outer = float(std::cos(glm::radians(outer_degrees)));
    l.spot_scale = 1.0f / std::max(0.001f, l.cos_inner - l.cos_outer);
    l.spot_offset = -l.cos_outer * l.spot_scale;
    return l;
}

PunctualLight directional_light(glm::vec3 direction, glm::vec3 irradiance) {
    PunctualLight l;
    l.type = PunctualType::Directional;
    l.direction = glm::normalize(direction);
    l.intensity = irradiance;
    return l;
}

// Irradiance at the floor point p (normal +Y) from `light`, unoccluded: I cosθ/d² × the spot's
// falloff, or E cosθ (KHR_lights_punctual; PBRT 4th ed. 12.1, 12.4).
glm::dvec3 punctual_irradiance(const PunctualLight& light, glm::dvec3 p) {
    if (light.type == PunctualType::Directional) {
        const double cos_theta = -double(light.direction.y);
        return cos_theta > 0.0 ? glm::dvec3(light.intensity) * cos_theta : glm::dvec3(0.0);
    }
    const glm::dvec3 to_light = glm::dvec3(light.position) - p;
    const double d2 = glm::dot(to_light, to_light);
    const glm::dvec3 wi = to_light / std::sqrt(d2);
    if (wi.y <= 0.0) return glm::dvec3(0.0);
    const double falloff = spot_attenuation(light, -glm::dot(wi, glm::dvec3(light.direction)));
    return glm::dvec3(light.intensity) * (wi.y * falloff / d2);
}

// A pixel's mean over renders and its standard error, from independent renders.
struct PixelStats {
    std::vector<double> mean, standard_error;  // 3 per pixel
    uint64_t nan_samples = 0;
};

PixelStats pixel_stats(const DeviceContext& device, const GpuSceneData& data,
                       RenderSettings settings, int count, uint32_t first_seed) {
    const size_t n = 3 * size_t(settings.width) * settings.height;
    std::vector<double> sum(n, 0.0), sum_sq(n, 0.0);
    PixelStats s;
    for (int k = 0; k < count; ++k) {
        settings.seed = first_seed + uint32_t(k);
        const RenderResult r = render(device, data, settings);
        s.nan_samples += r.nan_samples;
        for (size_t i = 0; i < n; ++i) {
            sum[i] += r.image.rgb[i];
            sum_sq[i] += double(r.image.rgb[i]) * r.image.rgb[i];
        }
    }
    s.mean.resize(n);
    s.standard_error.resize(n);
    for (size_t i = 0; i < n; ++i) {
        s.mean[i] = sum[i] / count;
        const double var = std::max(0.0, sum_sq[i] - sum[i] * sum[i] / count) / (count - 1);
        s.standard_error[i] = std::sqrt(var / count);
    }
    return s;
}

// The floor of PlaneScene (albedo (0.6, 0.5, 0.4), y = 0, seen from above) with `lights` and,
// when `area`, PlaneScene's two polygon lights: its exact image, averaged over each pixel's
// footprint.
struct PunctualPlane {
    PlaneScene ps;
    std::vector<PunctualLight> lights;

    PunctualPlane(std::vector<PunctualLight> punctual, bool area) : lights(std::move(punctual)) {
        if (!area) {
            ps.scene = Scene();
            ps.lights.clear();
            const uint32_t floor = add_material(ps.scene, glm::vec3(ps.albedo));
            add_quad(ps.scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
        }
        ps.scene.punctual_lights = lights;
    }

    std::vector<double> exact_image(int w, int h) const {
        std::vector<double> image = ps.exact_image(w, h);
        const std::vector<double> punctual = exact_plane_image(ps.camera, w, h, [&](glm::dvec3 p) {
            glm::dvec3 v(0.0);
            for (const PunctualLight& l : lights) v += ps.albedo / M_PI * punctual_irradiance(l, p);
            return v;
        });
        for (size_t i = 0; i < image.size(); ++i) image[i] += punctual[i];
        return image;
    }
};

const std::vector<PunctualLight> kPointAndSpot = {
    point_light({-0.4f, 1.0f, 0.3f}, {3.0f, 2.0f, 1.0f}),
    spot_light({0.5f, 1.2f, -0.3f}, {0.2f, -1.0f, 0.1f}, {5.0f, 5.0f, 4.0f}, 15.0, 35.0),
};

}  // namespace

TEST_CASE("a point and a spot light over a floor: albedo/pi x I cos/d^2 x falloff, pixel by pixel",
          "[punctual][render][analytic]") {
    DeviceContext device = first_device();
    const PunctualPlane scene(kPointAndSpot, false);
    RenderSettings settings = image_settings(12, 12, 32);
    const GpuSceneData data = gpu_scene_for(scene.ps.scene, scene.ps.camera, settings);
    REQUIRE(data.punctual.size() == 2);
    REQUIRE(data.lights.empty());
    const std::vector<double> exact = scene.exact_image(settings.width, settings.height);
    for (const char* estimator : {"light-area", "light-solid-angle", "mis"}) {
        settings.estimator = estimator;
        const PixelStats s = pixel_stats(device, data, settings, kPixelRenders, kFirstSeed);
        CHECK(s.nan_samples == 0);
        // Each value's deviation in its own standard errors (the midpoint rule of the exact image
        // is good to far below 1e-4 of the value): none far out, and their mean square near 1
        // (a bias of a fraction of a standard error in every pixel raises it).
        double largest = 0.0, z2 = 0.0, worst = 0.0;
        for (size_t i = 0; i < exact.size(); ++i) {
            const double z = (s.mean[i] - exact[i]) / (s.standard_error[i] + 1e-4 * exact[i]);
            z2 += z * z / double(exact.size());
            worst = std::max(worst, std::abs(z));
            largest = std::max(largest, exact[i]);
        }
        INFO(estimator << ": mean square deviation " << z2 << " standard errors², largest "
                       << worst);
        CHECK(worst < 5.5);
        CHECK(z2 < 1.4);
        // Not vacuous: the floor is lit, and the spot's cone edge crosses the image.
        CHECK(largest > 0.1);
    }
}

TEST_CASE("a directional light at an angle: albedo/pi x E cos, and a blocker's shadow is black",
          "[punctual][render][analytic]") {
    DeviceContext device = first_device();
    PunctualPlane scene({directional_light({1.0f, -1.0f, 0.0f}, {2.0f, 1.5f, 1.0f})}, false);
    // A box on the floor at x in [-0.2, 0.1], z in [-0.3, 0.3], 0.5 high: the light comes from
    // −X at 45°, so its top casts a shadow on x in [0.3, 0.6], which the camera sees past it.
    // Double-sided: the floor's shadow rays meet the top from below (a single-sided top would
    // be culled there and cast no shadow).
    const uint32_t grey = add_material(scene.ps.scene, glm::vec3(0.5f), glm::vec3(0.0f), true);
    const glm::vec3 lo(-0.2f, 0.0f, -0.3f), hi(0.1f, 0.5f, 0.3f);
    add_quad(scene.ps.scene, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z},
             {hi.x, hi.y, lo.z}, grey);  // top, facing +Y
    add_quad(scene.ps.scene, {lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z},
             {lo.x, hi.y, lo.z}, grey);  // the side facing the light (−X)
    RenderSettings settings = image_settings(16, 16, 16);
    const GpuSceneData data = gpu_scene_for(scene.ps.scene, scene.ps.camera, settings);
    // The camera (looking down from height 3, 40°) sees x, z in ±3 tan 20° = ±1.09.
    const double half = 3.0 * std::tan(glm::radians(20.0));
    auto pixel_of = [&](double x, double z) {
        const int i = int((x / half + 1.0) * 0.5 * settings.width);
        const int j = int((z / half + 1.0) * 0.5 * settings.height);  // image up = −Z
        return size_t(j) * settings.width + size_t(i);
    };
    const glm::dvec3 E(2.0, 1.5, 1.0);
    const double cos_theta = std::sqrt(0.5);
    const glm::dvec3 lit = scene.ps.albedo / M_PI * E * cos_theta;
    for (const char* estimator : {"light-area", "light-solid-angle", "mis"})
        for (const char* select : {"power", "tree"}) {
            settings.estimator = estimator;
            settings.light_select = select;
            settings.seed = 11;
            const RenderResult r = render(device, data, settings);
            INFO(estimator << " / " << select);
            CHECK(r.nan_samples == 0);
            // Well inside the lit floor and well inside the shadow: every sample of the pixel
            // sees the same (one light, pmf 1).
            for (auto [x, z] : {std::pair{-0.8, -0.8}, std::pair{-0.6, 0.7}, std::pair{0.9, 0.9}}) {
                const size_t p = pixel_of(x, z);
                for (int c = 0; c < 3; ++c)
                    CHECK(r.image.rgb[3 * p + c] == Approx(lit[c]).epsilon(1e-5));
            }
            const size_t shadow = pixel_of(0.45, 0.05);  // x in [0.41, 0.55], z in [0, 0.14]
            for (int c = 0; c < 3; ++c) CHECK(r.image.rgb[3 * shadow + c] == 0.0f);
        }
}

TEST_CASE("every light selection gives the same image of punctual and area lights",
          "[punctual][render][analytic]") {
    DeviceContext device = first_device();
    std::vector<PunctualLight> lights = kPointAndSpot;
    lights.push_back(point_light({1.0f, 0.6f, 0.8f}, {0.5f, 0.5f, 0.5f}));
    // Low from +Z, so that the area lights' shadows fall outside the view (z < -1.7), which
    // the exact image (no occlusion) assumes.
    lights.push_back(directional_light({0.0f, -1.0f, -3.0f}, {0.4f, 0.5f, 0.6f}));
    // A hard-edged spot (inner = outer): the tree must still reach inside its cone.
    lights.push_back(
        spot_light({-0.6f, 0.9f, -0.5f}, {0.0f, -1.0f, 0.0f}, {2.0f, 2.0f, 2.0f}, 25.0, 25.0));
    const PunctualPlane scene(lights, true);
    RenderSettings settings = image_settings(16, 16, 32);
    const glm::dvec3 exact = image_mean(scene.exact_image(settings.width, settings.height));
    for (const char* estimator : {"light-area", "mis"})
        for (const std::string& select : variant_names(kLightSelectVariants)) {
            settings.estimator = estimator;
            settings.light_select = select;
            GpuSceneData selected = gpu_scene_for(scene.ps.scene, scene.ps.camera, settings);
            for (const LightSelectVariant& v : kLightSelectVariants)
                if (v.name == select) build_light_selection(selected, v.id);
            REQUIRE(selected.lights.size() == 3);
            REQUIRE(selected.punctual.size() == 5);
            const Renders r = independent_renders(device, selected, settings, kRenders, kFirstSeed);
            check_unbiased(r, exact, std::string(estimator) + " / " + select);
            CHECK(r.standard_error.x < 0.03 * exact.x);
        }
}

TEST_CASE("the direction estimators cannot see punctual lights: a black image and one warning",
          "[punctual][cli]") {
    TempDir dir;
    const std::string scene = scene_path("punctual/point-light.gltf");
    for (const char* estimator :
         {"hemisphere-uniform", "hemisphere-cosine", "bsdf", "ambient-cosine", "light-area"}) {
        const std::string out = dir / (std::string(estimator) + ".exr");
        const ProcessResult r =
            run_process(MCRT_EXE,
                        {"render", scene, "--width", "16", "--height", "16", "--spp", "8",
                         "--estimator", estimator, "--out", out, "--quiet"},
                        dir.path());
        INFO(estimator << ": " << r.err);
        REQUIRE(r.exit_code == 0);
        const std::vector<std::string> warnings = lines_starting_with(r.err, "mcrt: warning:");
        const Image image = read_exr(out);
        double sum = 0.0;
        for (float v : image.rgb) sum += v;
        if (std::string(estimator) == "light-area") {
            CHECK(warnings.empty());
            CHECK(sum > 0.0);
            continue;
        }
        REQUIRE(warnings.size() == 1);
        CHECK(warnings[0].find(estimator) != std::string::npos);
        CHECK(warnings[0].find("1 KHR_lights_punctual light ") != std::string::npos);
        // The ambient estimators see their sky (1 by default), not the light.
        if (std::string(estimator) != "ambient-cosine") CHECK(sum == 0.0);
    }
}

TEST_CASE("punctual lights render the same bytes on one device or two", "[punctual][multidevice]") {
    std::vector<std::unique_ptr<DeviceContext>> owned;
    std::vector<const DeviceContext*> all;
    for (const DeviceInfo& d : enumerate_devices([](const std::string& w) { WARN(w); })) {
        owned.push_back(std::make_unique<DeviceContext>(d));
        all.push_back(owned.back().get());
    }
    REQUIRE(all.size() >= 2);
    std::vector<PunctualLight> lights = kPointAndSpot;
    lights.push_back(directional_light({-0.3f, -1.0f, 0.5f}, {0.4f, 0.5f, 0.6f}));
    const PunctualPlane scene(lights, true);
    RenderSettings settings = image_settings(40, 32, 48);
    settings.estimator = "mis";
    settings.light_select = "tree";
    settings.max_depth = 3;
    const GpuSceneData data =
        make_gpu_scene(scene.ps.scene, build_bvh(scene.ps.scene), scene.ps.camera, settings.width,
                       settings.height, LightSelection::Tree);
    const RenderResult one = render(std::vector<const DeviceContext*>{all[0]}, data, settings);
    const RenderResult both = render(all, data, settings);
    CHECK(std::memcmp(one.image.rgb.data(), both.image.rgb.data(),
                      one.image.rgb.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(one.image.variance.data(), both.image.variance.data(),
                      one.image.variance.size() * sizeof(float)) == 0);
    for (const DeviceReport& d : both.devices) CHECK(d.samples > 0);
}
