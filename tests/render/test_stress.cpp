// Stability where methods fail: the scenes of scenes/stress (scripts/scenes/make_stress_scenes.py)
// × every estimator × light selection render without NaN or Inf, and wherever an estimator's
// standard error means something on them, its image mean matches the exact image (Lambert's
// formula for every emitting triangle; the scenes have no occluders) within 4.5 standard errors
// from independent renders, as in test_estimators.cpp. What each scene stresses:
// scenes/stress/README.md.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "example_estimators.h"
#include "image/image.h"
#include "independent_renders.h"
#include "process_support.h"
#include "render/renderer.h"
#include "scene/gltf_import.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::vector<std::string> kStressScenes = {
    "tiny-bright-light", "near-light",          "grazing-light",      "light-facing-away",
    "many-lights",       "degenerate-emitters", "reflecting-emitters"};

std::string stress_path(const std::string& name) {
    return std::string(MCRT_SCENES) + "/stress/" + name + ".gltf";
}

Scene load_stress_scene(const std::string& name) {
    return load_gltf(stress_path(name), [](const std::string& w) { WARN(w); });
}

// ---- Exact images ------------------------------------------------------------------------------

struct ExactTriangle {
    glm::dvec3 p[3];
    glm::dvec3 n;  // unit front normal (counter-clockwise), zero for a degenerate triangle
    const Material* material;
};

std::vector<ExactTriangle> exact_triangles(const Scene& scene) {
    std::vector<ExactTriangle> out;
    for (size_t t = 0; t < scene.triangle_count(); ++t) {
        ExactTriangle e;
        for (int k = 0; k < 3; ++k) e.p[k] = glm::dvec3(scene.positions[3 * t + k]);
        glm::dvec3 c = glm::cross(e.p[1] - e.p[0], e.p[2] - e.p[0]);
        double len = glm::length(c);
        e.n = len > 0 ? c / len : glm::dvec3(0.0);
        e.material = &scene.materials[scene.triangle_material[t]];
        out.push_back(e);
    }
    return out;
}

// Sutherland–Hodgman: the part of `polygon` where dot(q − x, n) ≥ 0.
std::vector<glm::dvec3> clip_to_hemisphere(const std::vector<glm::dvec3>& polygon, glm::dvec3 x,
                                           glm::dvec3 n) {
    std::vector<glm::dvec3> out;
    for (size_t i = 0; i < polygon.size(); ++i) {
        glm::dvec3 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
        double da = glm::dot(a - x, n), db = glm::dot(b - x, n);
        if (da >= 0) out.push_back(a);
        if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
    }
    return out;
}

// Irradiance at x (normal n) from a polygon of unit radiance above x's horizon:
// E = 1/2 · |Σ Θ_i (Γ_i · n)| (Lambert 1760; Arvo 1995 eq. 1), skipping zero-length edges.
double lambert_irradiance(const std::vector<glm::dvec3>& polygon, glm::dvec3 x, glm::dvec3 n) {
    double sum = 0;
    for (size_t i = 0; i < polygon.size(); ++i) {
        glm::dvec3 a = glm::normalize(polygon[i] - x);
        glm::dvec3 b = glm::normalize(polygon[(i + 1) % polygon.size()] - x);
        glm::dvec3 c = glm::cross(a, b);
        double s = glm::length(c);
        if (!(s > 1e-15)) continue;
        sum += std::atan2(s, glm::dot(a, b)) * glm::dot(c / s, n);
    }
    return 0.5 * std::abs(sum);
}

// Reflected radiance at x (normal n facing the viewer, on triangle `self`): albedo/π × Σ Le·E
// over the emitting triangles x can see the front of (both sides when double-sided).
glm::dvec3 reflected(const std::vector<ExactTriangle>& tris, const ExactTriangle& self,
                     glm::dvec3 x, glm::dvec3 n) {
    glm::dvec3 sum(0.0);
    for (const ExactTriangle& e : tris) {
        glm::dvec3 Le(e.material->emission);
        if (&e == &self || Le == glm::dvec3(0.0)) continue;
        // Zero area: no irradiance. (The renderer keeps slivers over FLT_MIN; theirs is ~1e-6
        // of any pixel here.)
        if (glm::length(glm::cross(e.p[1] - e.p[0], e.p[2] - e.p[0])) < 1e-6) continue;
        if (!e.material->double_sided && glm::dot(e.n, x - e.p[0]) <= 0) continue;
        // In x's own plane (the other half of an emitting quad): in the horizon, no irradiance.
        double height = 0;
        for (const glm::dvec3& q : e.p) height = std::max(height, std::abs(glm::dot(q - x, n)));
        if (height < 1e-9) continue;
        std::vector<glm::dvec3> poly = clip_to_hemisphere({e.p[0], e.p[1], e.p[2]}, x, n);
        if (poly.size() < 3) continue;
        sum += Le * lambert_irradiance(poly, x, n);
    }
    return glm::dvec3(self.material->albedo) / M_PI * sum;
}

// Möller–Trumbore in double precision; degenerate triangles are never hit.
double intersect(const ExactTriangle& t, glm::dvec3 o, glm::dvec3 d) {
    glm::dvec3 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0], pv = glm::cross(d, e2);
    double det = glm::dot(e1, pv);
    if (std::abs(det) < 1e-300 || t.n == glm::dvec3(0.0)) return -1;
    glm::dvec3 tv = o - t.p[0];
    double u = glm::dot(tv, pv) / det;
    if (u < 0 || u > 1) return -1;
    glm::dvec3 qv = glm::cross(tv, e1);
    double v = glm::dot(d, qv) / det;
    if (v < 0 || u + v > 1) return -1;
    return glm::dot(e2, qv) / det;
}

// The pixel means the renderer estimates (DESIGN.md "Radiometric contract", direct modes):
// Le seen + reflected direct light, box filter as a midpoint rule over each pixel.
std::vector<double> exact_image(const Scene& scene, const Camera& camera, int w, int h) {
    std::vector<ExactTriangle> tris = exact_triangles(scene);
    // 32×32 points per pixel: the edges of the floor and the wall against the black background
    // cross pixels, and 8×8 leaves a quadrature error of about one standard error there.
    return exact_pixel_image(camera, w, h, 32, [&](glm::dvec3 eye, glm::dvec3 d) {
        const ExactTriangle* hit = nullptr;
        double t_hit = std::numeric_limits<double>::infinity();
        for (const ExactTriangle& t : tris) {
            double s = intersect(t, eye, d);
            if (s > 0 && s < t_hit) t_hit = s, hit = &t;
        }
        if (!hit) return glm::dvec3(0.0);
        glm::dvec3 p = eye + t_hit * d;
        bool front = glm::dot(hit->n, d) < 0;
        glm::dvec3 n = front ? hit->n : -hit->n;
        glm::dvec3 v = reflected(tris, *hit, p, n);
        if (front || hit->material->double_sided) v += glm::dvec3(hit->material->emission);
        return v;
    });
}

// ---- Renders -----------------------------------------------------------------------------------

// Every estimator of the table; the direct ones (not the sky's) have the exact image. (A
// function: the table is another translation unit's global, not yet built at static init.)
std::vector<EstimatorCase> all_variants() {
    std::vector<EstimatorCase> cases = estimator_cases(0);
    REQUIRE(cases.size() >= 9);
    return cases;
}

bool direct(const EstimatorCase& v) { return !v.uses(kUsesSky); }

std::string variant_name(const EstimatorCase& v, const std::string& select) {
    return v.label() + (v.uses(kUsesLightSelection) ? " / " + select : "");
}

std::string format(glm::dvec3 v) {
    std::ostringstream s;
    s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return s.str();
}

constexpr int kRenders = 16;
constexpr uint32_t kFirstSeed = 2000;  // renders use seeds 2000, 2001, ...

// The scene × estimator pairs that are the estimator's failure case at test sizes: too few
// hits (a light of 1e-4 sr, or one within 1° of the horizon for cosine sampling) for a standard
// error from 16 renders to mean anything. Only their stability is checked.
const std::set<std::pair<std::string, std::string>> kNoStandardError = {
    {"tiny-bright-light", "hemisphere-uniform"},
    {"tiny-bright-light", "hemisphere-cosine"},
    {"grazing-light", "hemisphere-cosine"},
};

// What makes each scene a stress: on it, the first variant's standard error is more than
// `factor` times the second's (measured, 16 renders: 44, 2000, 5.0, 4.3, 3.4).
struct Failure {
    const char* scene;
    const char* worse;
    const char* better;
    double factor;
    const char* why;
};

const Failure kFailures[] = {
    {"near-light", "light-area / power", "light-solid-angle / power", 10,
     "area sampling's cosθ cosθ'/d² with d down to 0.01"},
    {"tiny-bright-light", "hemisphere-cosine", "light-area / power", 100,
     "directions find a 1e-4 sr light about twice per 65536 samples, even with 8× the samples"},
    {"many-lights", "light-area / uniform", "light-area / power", 2,
     "uniform selection with radiances 10^6 apart"},
    {"light-facing-away", "light-area / power", "light-area / uniform", 2,
     "power selection ignores orientation: it mostly picks the light facing away"},
    // Measured 1.8-2.5x on the image mean (16 seeds, 32 spp, before and after the light sample
    // was shared by the choice and the point; 2.0-2.3x per pixel): 1.5 leaves room for the
    // noise of a ratio of two standard errors from 16 renders.
    {"reflecting-emitters", "light-area / power", "light-solid-angle / power", 1.5,
     "area sampling of the wall from floor points 0.02 below it"},
};

}  // namespace

TEST_CASE(
    "stress scenes: every estimator and light selection is finite and, where its error "
    "bar means something, unbiased",
    "[stress][estimators][analytic]") {
    DeviceContext device = first_device();
    RenderSettings settings;
    settings.width = 16;
    settings.height = 16;
    for (const std::string& name : kStressScenes) {
        Scene scene = load_stress_scene(name);
        REQUIRE(!scene.cameras.empty());
        Bvh bvh = build_bvh(scene);
        GpuSceneData data =
            make_gpu_scene(scene, bvh, scene.cameras.front(), settings.width, settings.height);
        glm::dvec3 exact = image_mean(exact_image(scene, scene.cameras.front(), 16, 16));
        std::map<std::string, Renders> ambient;
        std::map<std::string, double> standard_error;  // red channel, by variant_name
        for (const EstimatorCase& v : all_variants())
            for (const std::string& select : v.selections()) {
                v.apply(settings);
                settings.light_select = select;
                // Direction sampling finds small lights rarely: more samples (as test_estimators).
                bool directions = direct(v) && !v.uses(kUsesLightSelection);
                settings.spp = directions ? 256 : 32;
                Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
                std::string what = name + ": " + variant_name(v, select);
                INFO(what << ": mean " << format(r.mean) << ", exact " << format(exact)
                          << ", standard error " << format(r.standard_error));
                CHECK(r.nan_samples == 0);
                CHECK(r.non_finite_pixels == 0);
                standard_error[variant_name(v, select)] = r.standard_error.x;
                if (!direct(v)) {
                    ambient[v.row->name] = r;
                    continue;
                }
                if (kNoStandardError.count({name, v.row->name})) continue;
                for (int c = 0; c < 3; ++c)
                    CHECK(std::abs(r.mean[c] - exact[c]) <= 4.5 * r.standard_error[c]);
            }
        // Ambient light has no exact image here (the lights occlude the sky): the three
        // ambient estimators agree within 4.5 combined standard errors.
        const Renders& u = ambient["ambient-uniform"];
        for (const char* other : {"ambient-cosine", "ambient-fibonacci"}) {
            const Renders& o = ambient[other];
            INFO(name << ": ambient-uniform " << format(u.mean) << " ± " << format(u.standard_error)
                      << ", " << other << " " << format(o.mean) << " ± "
                      << format(o.standard_error));
            for (int c = 0; c < 3; ++c)
                CHECK(std::abs(u.mean[c] - o.mean[c]) <=
                      4.5 * std::hypot(u.standard_error[c], o.standard_error[c]));
        }
        for (const Failure& f : kFailures) {
            if (name != f.scene) continue;
            INFO(name << ": " << f.why << ": standard error of " << f.worse << " "
                      << standard_error.at(f.worse) << ", of " << f.better << " "
                      << standard_error.at(f.better));
            CHECK(standard_error.at(f.worse) > f.factor * standard_error.at(f.better));
        }
    }
}

TEST_CASE("stress scenes: every example estimator file is finite and unbiased",
          "[stress][estimators][analytic][estimator-file]") {
    DeviceContext device = first_device();
    RenderSettings settings = image_settings(16, 16, 32);
    const std::vector<std::string> files = example_estimator_files();
    REQUIRE(files.size() >= 2);
    for (const std::string& name : kStressScenes) {
        Scene scene = load_stress_scene(name);
        GpuSceneData data = make_gpu_scene(scene, build_bvh(scene), scene.cameras.front(),
                                           settings.width, settings.height);
        glm::dvec3 exact = image_mean(exact_image(scene, scene.cameras.front(), 16, 16));
        for (const std::string& file : files)
            for (const std::string& select : variant_names(kLightSelectVariants)) {
                use_estimator_file(settings, file);
                settings.light_select = select;
                // A file that samples no light finds small or grazing lights by its directions
                // alone, rarely: the built-in direction estimators' sample count (above).
                // bsdf_directions.cl at 32 spp found grazing-light's light 0 to 5 times in
                // 81920 samples, too few for its standard error to mean anything.
                bool directions =
                    settings.estimator_source.find("sample_light") == std::string::npos;
                settings.spp = directions ? 256 : 32;
                Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
                INFO(name << ": " << file << " / " << select << ": mean " << format(r.mean)
                          << ", exact " << format(exact) << ", standard error "
                          << format(r.standard_error));
                CHECK(r.nan_samples == 0);
                CHECK(r.non_finite_pixels == 0);
                for (int c = 0; c < 3; ++c)
                    CHECK(std::abs(r.mean[c] - exact[c]) <= 4.5 * r.standard_error[c]);
            }
    }
}

TEST_CASE("stress: a light facing away from the receiver adds exactly nothing",
          "[stress][estimators]") {
    // Without the dim light only the bright light facing up is left: every direct estimator,
    // whatever the selection, must give an image of exact zeros.
    DeviceContext device = first_device();
    Scene scene = load_stress_scene("light-facing-away");
    for (Material& m : scene.materials)
        if (m.name == "dim light") m.emission = glm::vec3(0.0f);
    RenderSettings settings = image_settings(16, 16, 64);
    Bvh bvh = build_bvh(scene);
    GpuSceneData data =
        make_gpu_scene(scene, bvh, scene.cameras.front(), settings.width, settings.height);
    REQUIRE(data.lights.size() == 2);
    for (const EstimatorCase& v : all_variants())
        for (const std::string& select : v.selections()) {
            if (!direct(v)) continue;
            v.apply(settings);
            settings.light_select = select;
            RenderResult r = render(device, data, settings);
            INFO(variant_name(v, select));
            CHECK(r.nan_samples == 0);
            size_t nonzero = 0;
            for (float x : r.image.rgb) nonzero += x != 0.0f ? 1 : 0;
            CHECK(nonzero == 0);
        }
}

TEST_CASE("stress: zero-area emitters are not lights", "[stress][scene]") {
    // Exactly degenerate triangles (a repeated index, a repeated vertex, one point, collinear
    // points) are dropped; the ordinary light's two triangles and the slivers of non-zero area
    // (double precision) stay. Power selection never picks a zero-power light.
    Scene scene = load_stress_scene("degenerate-emitters");
    std::vector<EmissiveTriangle> emitters = collect_emitters(scene);
    for (const EmissiveTriangle& e : emitters) {
        glm::dvec3 p0 = scene.positions[3 * e.triangle], p1 = scene.positions[3 * e.triangle + 1],
                   p2 = scene.positions[3 * e.triangle + 2];
        INFO("triangle " << e.triangle << ", area " << e.area);
        CHECK(glm::length(glm::cross(p1 - p0, p2 - p0)) > 0.0);
        CHECK(e.area > 0.0f);
        CHECK(e.power > 0.0f);
    }
    // floor 2 + light 2 + 8 degenerate ones; of these "collinear 3d", "float-collinear" and
    // "needle" have a non-zero area in double precision.
    REQUIRE(scene.triangle_count() == 12);
    CHECK(emitters.size() == 5);
    Bvh bvh = build_bvh(scene);
    GpuSceneData data = make_gpu_scene(scene, bvh, scene.cameras.front(), 16, 16);
    REQUIRE(data.light_selection.cdf.size() == emitters.size() + 1);
    for (size_t i = 0; i < emitters.size(); ++i)
        CHECK(data.light_selection.cdf[i + 1] > data.light_selection.cdf[i]);
}

TEST_CASE("stress scenes through the executable: exit 0, finite EXR, nan_samples 0",
          "[stress][cli]") {
    TempDir tmp("mcrt-stress");
    for (const std::string& name : kStressScenes)
        for (const std::string& estimator : variant_names(kEstimatorVariants)) {
            // Uniform selection picks the slivers and the dim lights as often as any other.
            std::string exr = tmp / (name + ".exr"), stats = tmp / (name + ".json");
            std::vector<std::string> args = {"render",         stress_path(name),
                                             "--out",          exr,
                                             "--width",        "16",
                                             "--height",       "16",
                                             "--spp",          "16",
                                             "--estimator",    estimator,
                                             "--light-select", "uniform",
                                             "--seed",         "7",
                                             "--stats",        stats,
                                             "--quiet"};
            ProcessResult r = run_process(MCRT_EXE, args, tmp.path(), 60.0);
            INFO(name << " / " << estimator << ": " << r.err);
            REQUIRE(r.exit_code == 0);
            Image image = read_exr(exr);
            size_t non_finite = 0;
            for (size_t i = 0; i < image.rgb.size(); ++i)
                non_finite +=
                    std::isfinite(image.rgb[i]) && std::isfinite(image.variance[i]) ? 0 : 1;
            CHECK(non_finite == 0);
            nlohmann::json j = nlohmann::json::parse(read_whole_file(stats));
            CHECK(j.at("nan_samples").get<uint64_t>() == 0);
        }
}
