// Rays that leave surfaces at every scale (kernels/core/geometry.cl, intersect.cl): the quad light
// over floors 1 m to 100 km wide, the whole scene scaled from 10^-3 to 10^3 and moved up to 10^4 m
// from the origin, a grazing view over large floors, a large emitting plane, and a box resting
// on a floor — each against its exact image (Lambert's formula), band by band, within the
// renders' own standard errors, for every strategy that spawns rays.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <sstream>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

// 20 renders, so that the standard error read off their spread is itself good to about 16%
// (a t distribution with 19 degrees of freedom: 4.5 of them are exceeded with probability 2e-4).
constexpr int kRenders = 20;
constexpr uint32_t kFirstSeed = 90000;
// Each check takes the next kRenders seeds, so that no two checks share random numbers (one
// unlucky draw would otherwise repeat in every scene).
uint32_t next_seed = kFirstSeed;
constexpr int kSize = 16;  // image width and height
constexpr int kBands = 4;  // horizontal bands of kSize / kBands rows, each checked on its own

// Where a scene designed around the origin in metres is put: p ↦ scale·p + shift, rounded to
// float as the scene stores it. The exact images use the rounded positions.
struct Placement {
    double scale = 1.0;
    glm::dvec3 shift{0.0};
    glm::dvec3 operator()(glm::dvec3 p) const { return glm::dvec3(glm::vec3(scale * p + shift)); }
    std::string label() const {
        std::ostringstream s;
        s << "scale " << scale << ", shift (" << shift.x << ", " << shift.y << ", " << shift.z
          << ")";
        return s.str();
    }
};

Camera camera_at(glm::dvec3 eye, glm::dvec3 at, double yfov) {
    const glm::dvec3 forward = glm::normalize(at - eye);
    const glm::dvec3 hint = std::abs(forward.y) > 0.9 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, hint));
    const glm::dvec3 up = glm::cross(right, forward);
    Camera c;
    c.camera_to_world = glm::mat4(glm::dmat4(glm::dvec4(right, 0), glm::dvec4(up, 0),
                                             glm::dvec4(-forward, 0), glm::dvec4(eye, 1)));
    c.yfov = float(yfov);
    return c;
}

// One strategy that spawns rays, at a depth: the direct-light estimators, and MIS along paths.
struct Strategy {
    const char* estimator;
    uint32_t max_depth;
    uint32_t spp;  // BSDF sampling finds small lights rarely: it gets more samples
    std::string label() const {
        return std::string(estimator) + " at depth " + std::to_string(max_depth);
    }
};

const std::vector<Strategy> kStrategies = {{"light-area", 1, 32},
                                           {"light-solid-angle", 1, 32},
                                           {"mis", 1, 32},
                                           {"bsdf", 1, 128},
                                           {"mis", 8, 32}};

// Exact pixel values from value(eye, d) over each pixel's footprint (64×64 midpoint rule), and the
// same with 32×32: their difference bounds the rule's own error, which the tolerance adds.
struct ExactImage {
    std::vector<double> fine, quadrature_error;
};

ExactImage exact_image(const Camera& camera,
                       const std::function<glm::dvec3(glm::dvec3, glm::dvec3)>& value) {
    ExactImage e;
    std::vector<double> coarse = exact_pixel_image(camera, kSize, kSize, 32, value);
    e.fine = exact_pixel_image(camera, kSize, kSize, 64, value);
    e.quadrature_error.resize(e.fine.size());
    for (size_t i = 0; i < e.fine.size(); ++i)
        e.quadrature_error[i] = std::abs(e.fine[i] - coarse[i]);
    return e;
}

// Mean of channel c over band b of an image of 3 values per pixel.
double band_mean(const std::vector<double>& img, int b, int c) {
    const int rows = kSize / kBands;
    double sum = 0;
    for (int j = b * rows; j < (b + 1) * rows; ++j)
        for (int i = 0; i < kSize; ++i) sum += img[3 * (size_t(j) * kSize + i) + c];
    return sum / double(rows * kSize);
}

// Every band of the image mean within 4.5 standard errors (from kRenders independent renders)
// plus the quadrature's error of the exact value, and no non-finite sample.
void check_bands(const DeviceContext& device, const GpuSceneData& data, RenderSettings settings,
                 const ExactImage& exact, const std::string& what) {
    std::vector<double> sum(3 * kBands, 0.0), sum_sq(3 * kBands, 0.0);
    uint64_t nan_samples = 0;
    const uint32_t first_seed = next_seed;
    next_seed += kRenders;
    for (int k = 0; k < kRenders; ++k) {
        settings.seed = first_seed + uint32_t(k);
        RenderResult result = render(device, data, settings);
        nan_samples += result.nan_samples;
        std::vector<double> rgb(result.image.rgb.begin(), result.image.rgb.end());
        for (int b = 0; b < kBands; ++b)
            for (int c = 0; c < 3; ++c) {
                double m = band_mean(rgb, b, c);
                sum[3 * b + c] += m;
                sum_sq[3 * b + c] += m * m;
            }
    }
    CHECK(nan_samples == 0);
    for (int b = 0; b < kBands; ++b)
        for (int c = 0; c < 3; ++c) {
            const double mean = sum[3 * b + c] / kRenders;
            const double var =
                std::max(0.0, (sum_sq[3 * b + c] - kRenders * mean * mean) / (kRenders - 1));
            const double se = std::sqrt(var / kRenders);
            const double value = band_mean(exact.fine, b, c);
            const double quadrature = band_mean(exact.quadrature_error, b, c);
            INFO(what << ", band " << b << " channel " << c << ": mean " << mean << ", exact "
                      << value << ", standard error " << se << ", z "
                      << (se > 0 ? (mean - value) / se : 0.0));
            // Where a strategy has no variance (BSDF sampling under an emitter filling the
            // hemisphere) only float rounding is left: the kernels' per-sample arithmetic and
            // sums of 16 in float, a few ulps of the value.
            const double rounding = 1e-5 * std::abs(value);
            CHECK(std::abs(mean - value) <= 4.5 * se + quadrature + rounding);
        }
}

void check_all_strategies(const DeviceContext& device, const Scene& scene, const Camera& camera,
                          const ExactImage& exact, const std::string& what,
                          const std::vector<Strategy>& strategies = kStrategies) {
    RenderSettings settings;
    settings.width = settings.height = kSize;
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    for (const Strategy& s : strategies) {
        settings.estimator = s.estimator;
        settings.max_depth = s.max_depth;
        settings.spp = s.spp;
        check_bands(device, data, settings, exact, what + ", " + s.label());
    }
}

const glm::dvec3 kAlbedo{0.6, 0.5, 0.4};

// The quad light of the estimator tests: a 0.5 m square of radiance 10 facing down, 1 m above a
// Lambertian floor of width `floor_width` centred under it.
struct QuadOverFloor {
    Scene scene;
    std::vector<glm::dvec3> light;  // the placed polygon
    double floor_y = 0, floor_half = 0;
    glm::dvec3 floor_centre{0.0};
    glm::dvec3 Le{10.0};

    QuadOverFloor(double floor_width, const Placement& place) {
        const double h = floor_width / 2;
        uint32_t floor = add_material(scene, glm::vec3(kAlbedo));
        glm::dvec3 f[4] = {place({-h, 0, -h}), place({-h, 0, h}), place({h, 0, h}),
                           place({h, 0, -h})};
        add_quad(scene, glm::vec3(f[0]), glm::vec3(f[1]), glm::vec3(f[2]), glm::vec3(f[3]), floor);
        floor_y = f[0].y;
        floor_half = h * place.scale;
        floor_centre = place({0, 0, 0});
        light = {place({-0.25, 1, -0.25}), place({0.25, 1, -0.25}), place({0.25, 1, 0.25}),
                 place({-0.25, 1, 0.25})};
        uint32_t m = add_material(scene, glm::vec3(0.0f), glm::vec3(Le));
        add_quad(scene, glm::vec3(light[0]), glm::vec3(light[1]), glm::vec3(light[2]),
                 glm::vec3(light[3]), m);
    }

    // albedo/π · E at the point where the ray eye + t·d meets the floor, 0 where it misses it.
    glm::dvec3 value(glm::dvec3 eye, glm::dvec3 d) const {
        const double t = (floor_y - eye.y) / d.y;
        if (!(t > 0)) return glm::dvec3(0.0);
        glm::dvec3 p = eye + t * d;
        if (std::abs(p.x - floor_centre.x) > floor_half ||
            std::abs(p.z - floor_centre.z) > floor_half)
            return glm::dvec3(0.0);
        p.y = floor_y;
        return kAlbedo / M_PI * Le * lambert_irradiance(light, p, {0, 1, 0}, 1.0);
    }

    ExactImage exact(const Camera& camera) const {
        return exact_image(camera, [&](glm::dvec3 e, glm::dvec3 d) { return value(e, d); });
    }
};

// Straight down from 0.9 m, seeing the middle 2 m of the floor (and beyond the edges of a
// floor 1 m wide).
Camera view_down(const Placement& place) {
    return camera_at(place({0, 0.9, 0}), place({0, 0, 0}), 2 * std::atan(1.0 / 0.9));
}

// From 0.6 m high looking 1.1 m ahead, 60° field of view: the floor from 0.37 m to the horizon,
// where shadow rays leave the floor at grazing angles.
Camera view_grazing(const Placement& place) {
    return camera_at(place({0, 0.6, 0}), place({0, 0, 1.1}), M_PI / 3);
}

// The quad light over floors of each width, seen by `view`, every strategy against the exact image.
void check_floors(std::initializer_list<double> widths, Camera (*view)(const Placement&),
                  const std::string& view_name) {
    DeviceContext device = first_device();
    for (double width : widths) {
        QuadOverFloor q(width, Placement{});
        Camera camera = view(Placement{});
        check_all_strategies(device, q.scene, camera, q.exact(camera),
                             "floor " + std::to_string(width) + " m, " + view_name);
    }
}

}  // namespace

TEST_CASE("floors from 1 m to 100 km wide render the quad light's exact image",
          "[offsets][analytic]") {
    check_floors({1.0, 10.0, 100.0, 1e3, 1e4, 1e5}, view_down, "view down");
}

TEST_CASE("floors seen at grazing angles render the quad light's exact image",
          "[offsets][analytic]") {
    check_floors({20.0, 2e3, 2e5}, view_grazing, "grazing view");
}

TEST_CASE("whole scenes scaled from 1e-3 to 1e3 and moved 1e4 m render the same exact image",
          "[offsets][analytic]") {
    DeviceContext device = first_device();
    std::vector<Placement> placements;
    for (double s : {1e-3, 1e-2, 1e-1, 1e1, 1e2, 1e3}) placements.push_back({s, glm::dvec3(0.0)});
    for (double d : {1e2, 1e3, 1e4}) placements.push_back({1.0, glm::dvec3(d, 0.5 * d, -0.7 * d)});
    placements.push_back({1e3, glm::dvec3(1e4, 0.5e4, -0.7e4)});
    for (const Placement& place : placements) {
        QuadOverFloor q(20.0, place);
        Camera camera = view_down(place);
        check_all_strategies(device, q.scene, camera, q.exact(camera), place.label());
        Camera grazing = view_grazing(place);
        check_all_strategies(device, q.scene, grazing, q.exact(grazing),
                             place.label() + ", grazing view");
    }
}

TEST_CASE("a large emitting plane over a large floor renders its exact image",
          "[offsets][analytic]") {
    // A 2 km square of radiance (1, 2, 0.5) 1 m above a 2 km floor: E = Lambert's polygon formula,
    // nearly π·L. Its light-area and solid-angle densities are hopeless on it (a sample lands near
    // the receiver once in 10^6; the solid angle is beyond Arvo's range and falls back to area),
    // so the strategies are BSDF sampling and MIS, where the BSDF sample carries the estimate and
    // the light samples still aim shadow rays at far points of the plane.
    DeviceContext device = first_device();
    Scene scene;
    const double h = 1000;
    const glm::dvec3 Le(1.0, 2.0, 0.5);
    uint32_t floor = add_material(scene, glm::vec3(kAlbedo));
    add_quad(scene, {-h, 0, -h}, {-h, 0, h}, {h, 0, h}, {h, 0, -h}, floor);
    std::vector<glm::dvec3> light = {{-h, 1, -h}, {h, 1, -h}, {h, 1, h}, {-h, 1, h}};
    uint32_t m = add_material(scene, glm::vec3(0.0f), glm::vec3(Le));
    add_quad(scene, glm::vec3(light[0]), glm::vec3(light[1]), glm::vec3(light[2]),
             glm::vec3(light[3]), m);
    for (const Camera& camera : {camera_at({0, 0.5, 0}, {0, 0, 0}, 2 * std::atan(0.3 / 0.5)),
                                 camera_at({0, 0.5, 0}, {0, 0, 1.0}, M_PI / 3)}) {
        ExactImage exact = exact_image(camera, [&](glm::dvec3 eye, glm::dvec3 d) {
            // A ray that rises meets the emitter's plane: the camera sees its radiance there.
            if (d.y > 0) {
                glm::dvec3 q = eye + ((1.0 - eye.y) / d.y) * d;
                return std::abs(q.x) <= h && std::abs(q.z) <= h ? Le : glm::dvec3(0.0);
            }
            glm::dvec3 p = eye + (-eye.y / d.y) * d;
            if (std::abs(p.x) > h || std::abs(p.z) > h) return glm::dvec3(0.0);
            p.y = 0;
            return kAlbedo / M_PI * Le * lambert_irradiance(light, p, {0, 1, 0}, 1.0);
        });
        check_all_strategies(device, scene, camera, exact, "emitting plane 2 km wide",
                             {{"bsdf", 1, 32}, {"mis", 1, 32}, {"mis", 8, 32}});
    }
}

TEST_CASE("no light leaks into a box resting on a large floor, and none is lost beside it",
          "[offsets][analytic]") {
    // A closed unit box (four walls and a lid, albedo 0.5) on a 2 km floor, a 0.5 m square light
    // of radiance 10 facing it from 1 m beside its wall, its lower edge 5 cm above the floor, so
    // that shadow rays from inside pass the wall a fraction of a millimetre above the contact.
    // Inside, every sample of every strategy is exactly 0; outside, between wall and light, the
    // floor sees the whole light (Lambert's formula), up to the contact line.
    DeviceContext device = first_device();
    for (const Placement& place : {Placement{}, Placement{1e3, glm::dvec3(0.0)},
                                   Placement{1.0, glm::dvec3(1e4, 0.5e4, -0.7e4)}}) {
        Scene scene;
        uint32_t floor = add_material(scene, glm::vec3(kAlbedo));
        // Double-sided: a single-sided wall is not there from inside the box (glTF's culling).
        uint32_t wall = add_material(scene, glm::vec3(0.5f), glm::vec3(0.0f), true);
        const double h = 1000;
        auto P = [&](double x, double y, double z) { return glm::vec3(place({x, y, z})); };
        add_quad(scene, P(-h, 0, -h), P(-h, 0, h), P(h, 0, h), P(h, 0, -h), floor);
        // Outward-facing walls x = ±0.5, z = ±0.5 and the lid y = 1, counter-clockwise from
        // outside.
        add_quad(scene, P(0.5, 0, -0.5), P(0.5, 1, -0.5), P(0.5, 1, 0.5), P(0.5, 0, 0.5), wall);
        add_quad(scene, P(-0.5, 0, 0.5), P(-0.5, 1, 0.5), P(-0.5, 1, -0.5), P(-0.5, 0, -0.5), wall);
        add_quad(scene, P(0.5, 0, 0.5), P(0.5, 1, 0.5), P(-0.5, 1, 0.5), P(-0.5, 0, 0.5), wall);
        add_quad(scene, P(-0.5, 0, -0.5), P(-0.5, 1, -0.5), P(0.5, 1, -0.5), P(0.5, 0, -0.5), wall);
        add_quad(scene, P(-0.5, 1, -0.5), P(-0.5, 1, 0.5), P(0.5, 1, 0.5), P(0.5, 1, -0.5), wall);
        // The light in the plane x = 1.5, facing −x.
        std::vector<glm::dvec3> light = {place({1.5, 0.05, -0.25}), place({1.5, 0.05, 0.25}),
                                         place({1.5, 0.55, 0.25}), place({1.5, 0.55, -0.25})};
        const glm::dvec3 Le(10.0);
        uint32_t m = add_material(scene, glm::vec3(0.0f), glm::vec3(Le));
        add_quad(scene, glm::vec3(light[0]), glm::vec3(light[1]), glm::vec3(light[2]),
                 glm::vec3(light[3]), m);

        const std::vector<Strategy> strategies = {
            {"light-area", 1, 32}, {"light-solid-angle", 1, 32},  {"mis", 1, 32},
            {"bsdf", 1, 128},      {"hemisphere-cosine", 1, 128}, {"mis", 8, 32}};

        // Inside: the floor to the wall bases, from under the lid.
        Camera inside = camera_at(place({0, 0.9, 0}), place({0, 0, 0}), 2 * std::atan(0.5 / 0.9));
        RenderSettings settings;
        settings.width = settings.height = kSize;
        GpuSceneData data = gpu_scene_for(scene, inside, settings);
        for (const Strategy& s : strategies) {
            settings.estimator = s.estimator;
            settings.max_depth = s.max_depth;
            settings.spp = s.spp;
            settings.seed = kFirstSeed;
            RenderResult r = render(device, data, settings);
            size_t lit = 0;
            for (float v : r.image.rgb) lit += v != 0.0f ? 1 : 0;
            INFO(place.label() << ", inside the box, " << s.label() << ": " << lit
                               << " values not 0");
            CHECK(lit == 0);
            CHECK(r.nan_samples == 0);
        }

        // Outside: the floor from the wall base (x = 0.5) to x = 1.4, below the light.
        const double floor_y = place({0, 0, 0}).y;
        Camera outside =
            camera_at(place({0.95, 0.9, 0}), place({0.95, 0, 0}), 2 * std::atan(0.45 / 0.9));
        ExactImage exact = exact_image(outside, [&](glm::dvec3 eye, glm::dvec3 d) {
            glm::dvec3 p = eye + ((floor_y - eye.y) / d.y) * d;
            p.y = floor_y;
            return kAlbedo / M_PI * Le * lambert_irradiance(light, p, {0, 1, 0}, 1.0);
        });
        // Direct light only: along longer paths the lit wall lights the floor too.
        check_all_strategies(device, scene, outside, exact, place.label() + ", beside the box",
                             {strategies.begin(), strategies.end() - 1});
    }
}

TEST_CASE(
    "ambient occlusion next to a wall is exact on floors up to 200 km and far from the origin",
    "[offsets][analytic]") {
    // The ambient estimators' scene (a wall x = 0 of height 1 and width 3 on a floor, under a
    // uniform sky) on large floors and moved away from the origin: at a floor point the
    // unoccluded share of (1/π)∫cosθ dω is 1 − F, F the wall's form factor.
    DeviceContext device = first_device();
    const glm::dvec3 albedo(0.7, 0.6, 0.5), sky(1.0, 2.0, 0.5);
    struct Case {
        double floor_width;
        Placement place;
    };
    for (const Case& k :
         {Case{6.0, {}}, Case{2e3, {}}, Case{2e5, {}},
          Case{2e3, {1.0, glm::dvec3(1e4, 0.5e4, -0.7e4)}}, Case{2e3, {1e3, glm::dvec3(0.0)}}}) {
        const Placement& place = k.place;
        auto P = [&](double x, double y, double z) { return glm::vec3(place({x, y, z})); };
        Scene scene;
        const double h = k.floor_width / 2;
        add_quad(scene, P(-h, 0, -h), P(-h, 0, h), P(h, 0, h), P(h, 0, -h),
                 add_material(scene, glm::vec3(albedo)));
        std::vector<glm::dvec3> wall = {place({0, 0, -1.5}), place({0, 1, -1.5}),
                                        place({0, 1, 1.5}), place({0, 0, 1.5})};
        add_quad(scene, glm::vec3(wall[0]), glm::vec3(wall[1]), glm::vec3(wall[2]),
                 glm::vec3(wall[3]), add_material(scene, glm::vec3(0.3f)));
        // From 0.5 m beside the wall, down onto the floor up to its base.
        Camera camera = camera_at(place({0.5, 1.0, 0}), place({0.5, 0, 0}), 2 * std::atan(0.5));
        const double floor_y = place({0, 0, 0}).y;
        ExactImage exact = exact_image(camera, [&](glm::dvec3 eye, glm::dvec3 d) {
            glm::dvec3 p = eye + ((floor_y - eye.y) / d.y) * d;
            p.y = floor_y;
            const double form_factor = lambert_irradiance(wall, p, {0, 1, 0}, 1.0) / M_PI;
            return albedo * sky * (1.0 - form_factor);
        });
        RenderSettings settings;
        settings.width = settings.height = kSize;
        settings.sky = glm::vec3(sky);
        GpuSceneData data = gpu_scene_for(scene, camera, settings);
        for (const char* estimator : {"ambient-uniform", "ambient-cosine"}) {
            settings.estimator = estimator;
            settings.spp = 32;
            check_bands(device, data, settings, exact,
                        "floor " + std::to_string(k.floor_width) + " m, " + place.label() + ", " +
                            estimator);
        }
    }
}
