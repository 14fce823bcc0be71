// The environment map as a light (--env): every estimator that sees it renders a constant map's
// furnace and a band of rows' closed-form floor within its standard error, environment sampling
// beats cosine sampling on a sun map, the choice beside the area lights has its exact pmf, and
// `mcrt render --env` refuses the hostile files with one line and exit 2.
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "analytic_scenes.h"
#include "device_support.h"
#include "image/image.h"
#include "independent_renders.h"
#include "process_support.h"
#include "render/environment_light.h"
#include "render/plan.h"
#include "scene_builders.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kRenders = 8;
constexpr uint32_t kFirstSeed = 3100;

// A map of w × h texels, texel (i, j) of radiance value(i, j) (grey), as an EXR in `dir`.
template <typename F>
std::string write_map(const TempDir& dir, const std::string& name, int w, int h, F value) {
    Image image(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            for (int c = 0; c < 3; ++c) image.rgb[3 * (size_t(j) * w + i) + c] = value(i, j, c);
    const std::string path = dir / name;
    write_exr(path, image);
    return path;
}

const Camera kCamera = looking_down(glm::vec3(0, 3, 0), glm::radians(40.0f));

RenderSettings env_settings(const std::string& env) {
    RenderSettings settings = image_settings(8, 8, 32);
    settings.env = env;
    return settings;
}

// Within 4.5 standard errors of the renders' means, or equal up to float rounding where a
// strategy has no variance (cosine directions under a constant map).
void check_close(const Renders& r, glm::dvec3 exact, const std::string& what) {
    INFO(what << ": mean (" << r.mean.x << ", " << r.mean.y << ", " << r.mean.z << "), exact ("
              << exact.x << ", " << exact.y << ", " << exact.z << "), standard error ("
              << r.standard_error.x << ", " << r.standard_error.y << ", " << r.standard_error.z
              << ")");
    CHECK(r.nan_samples == 0);
    for (int c = 0; c < 3; ++c)
        CHECK(std::abs(r.mean[c] - exact[c]) <= 4.5 * r.standard_error[c] + 2e-5 * exact[c]);
}

}  // namespace

TEST_CASE("a constant map is a furnace: every estimator renders albedo x L at every depth",
          "[environment][paths][analytic]") {
    DeviceContext device = first_device();
    TempDir dir("mcrt-env");
    const glm::dvec3 albedo(0.7, 0.5, 0.3), L(1.0, 2.0, 0.5);
    const std::string env =
        write_map(dir, "constant.exr", 8, 4, [&](int, int, int c) { return float(L[c]); });
    RenderSettings settings = env_settings(env);
    for (bool hidden_light : {false, true}) {
        const Scene scene = floor_scene(albedo, hidden_light);
        const GpuSceneData data = gpu_scene_for(scene, kCamera, settings);
        for (const EstimatorCase& v : estimator_cases(kUsesSkyLight))
            for (const std::string& selection : v.selections())
                for (uint32_t depth : {1u, 4u}) {
                    v.apply(settings);
                    settings.light_select = selection;
                    settings.max_depth = depth;
                    REQUIRE(make_render_plan(settings, data)
                                .program_options.find("-D MCRT_ENVIRONMENT_MAP") !=
                            std::string::npos);
                    Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
                    check_close(r, albedo * L,
                                v.label() + " / " + selection + " at depth " +
                                    std::to_string(depth) +
                                    (hidden_light ? ", beside an area light" : ", the map alone"));
                }
        // The ambient estimators take the map as their sky: albedo × L where it is unoccluded.
        settings.max_depth = 1;
        for (const EstimatorCase& v : estimator_cases(kUsesSky)) {
            v.apply(settings);
            Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
            check_close(r, albedo * L, v.label() + " under the map");
        }
    }
}

TEST_CASE("a band of rows lights an open floor with the closed-form radiance",
          "[environment][analytic]") {
    // Rows 1-2 of 8 bright, the rest dim: the floor's radiance is albedo/π × Σ over the rows above
    // the horizon of L_row × π (sin²θ_{j+1} − sin²θ_j), ∫cosθ dω over a whole row. A turn about +Y
    // changes nothing.
    DeviceContext device = first_device();
    TempDir dir("mcrt-env");
    const int w = 16, h = 8;
    auto row_radiance = [](int j) { return j == 1 || j == 2 ? 20.0 : 0.25; };
    const std::string env = write_map(dir, "band.exr", w, h, [&](int, int j, int c) {
        return float(row_radiance(j) * (c == 1 ? 0.5 : 1.0));
    });
    double E = 0.0;
    for (int j = 0; j < h / 2; ++j) {
        const double s0 = std::sin(kPi * j / h), s1 = std::sin(kPi * (j + 1) / h);
        E += row_radiance(j) * kPi * (s1 * s1 - s0 * s0);
    }
    const glm::dvec3 albedo(0.6);
    const glm::dvec3 exact = albedo / kPi * E * glm::dvec3(1.0, 0.5, 1.0);
    RenderSettings settings = env_settings(env);
    settings.env_rotate = 37.0f;
    settings.spp = 64;
    const Scene scene = floor_scene(albedo, true);
    const GpuSceneData data = gpu_scene_for(scene, kCamera, settings);
    for (const char* estimator :
         {"light-area", "light-solid-angle", "mis", "bsdf", "hemisphere-cosine"}) {
        settings.estimator = estimator;
        for (const char* selection : {"power", "uniform", "tree"}) {
            settings.light_select = selection;
            Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
            check_close(r, exact, std::string(estimator) + " / " + selection);
            if (std::string(estimator).rfind("light", 0) != 0) break;  // no light choice
        }
    }
}

TEST_CASE("a wall's shadow under a map of bright columns: the sampled and the looked-up map agree",
          "[environment]") {
    // The light strategies take a direction and its radiance from the texel CDF, the direction
    // estimators look the map up along theirs: a wall that hides part of a turned map from the
    // floor makes any mismatch of the two (a mirrored or shifted φ, a wrong turn) show.
    DeviceContext device = first_device();
    TempDir dir("mcrt-env");
    const std::string env = write_map(dir, "columns.exr", 16, 8, [](int i, int j, int c) {
        return (i >= 2 && i <= 4 && j >= 2 && j <= 3) ? 30.0f : c == 2 ? 1.0f : 0.5f;
    });
    RenderSettings settings = env_settings(env);
    settings.env_rotate = 50.0f;
    settings.spp = 128;
    Scene scene = floor_scene(glm::dvec3(0.5), false);
    // The wall blocks from both sides: double-sided (a single-sided one is culled from behind).
    Material wall = scene.materials[0];
    wall.double_sided = true;
    scene.materials.push_back(wall);
    add_quad(scene, {0.3f, 0, -3}, {0.3f, 1.5f, -3}, {0.3f, 1.5f, 3}, {0.3f, 0, 3},
             uint32_t(scene.materials.size() - 1));
    const GpuSceneData data = gpu_scene_for(scene, kCamera, settings);
    settings.estimator = "hemisphere-cosine";
    const Renders looked_up = independent_renders(device, data, settings, kRenders, kFirstSeed);
    for (const char* estimator : {"light-area", "mis"}) {
        settings.estimator = estimator;
        const Renders sampled = independent_renders(device, data, settings, kRenders, kFirstSeed);
        for (int c = 0; c < 3; ++c) {
            const double se = std::hypot(looked_up.standard_error[c], sampled.standard_error[c]);
            INFO(estimator << " channel " << c << ": " << sampled.mean[c] << " against "
                           << looked_up.mean[c] << " +- " << se);
            CHECK(std::abs(sampled.mean[c] - looked_up.mean[c]) <= 4.5 * se);
        }
    }
    // Not vacuous: the same map unturned gives another image mean.
    settings.env_rotate = 0.0f;
    settings.estimator = "light-area";
    const Renders unturned = independent_renders(device, data, settings, kRenders, kFirstSeed);
    const double se = std::hypot(looked_up.standard_error.x, unturned.standard_error.x);
    CHECK(std::abs(unturned.mean.x - looked_up.mean.x) > 6.0 * se);
}

TEST_CASE("on a sun map environment sampling is 100x as efficient as cosine sampling",
          "[environment]") {
    // Two texels 10^4 times brighter than a dim sky. Efficiency per sample: 1 / the variance of
    // the pixel mean at equal samples (one light or direction sample each; MIS takes one of
    // each).
    DeviceContext device = first_device();
    TempDir dir("mcrt-env");
    const std::string env = write_map(dir, "sun.exr", 64, 32, [](int i, int j, int) {
        return j == 8 && (i == 10 || i == 11) ? 1e4f : 1.0f;
    });
    RenderSettings settings = env_settings(env);
    settings.width = 16;
    settings.height = 16;
    settings.spp = 64;
    const Scene scene = floor_scene(glm::dvec3(0.5), false);
    const GpuSceneData data = gpu_scene_for(scene, kCamera, settings);
    auto variance = [&](const char* estimator) {
        settings.estimator = estimator;
        Renders r = independent_renders(device, data, settings, 4, kFirstSeed);
        CHECK(r.nan_samples == 0);
        return r.mean_layer_variance;
    };
    const double env_sampling = variance("light-area"), cosine = variance("hemisphere-cosine"),
                 bsdf = variance("bsdf"), mis = variance("mis");
    INFO("variance of the pixel mean: light-area " << env_sampling << ", hemisphere-cosine "
                                                   << cosine << ", bsdf " << bsdf << ", mis "
                                                   << mis);
    CHECK(cosine / env_sampling >= 100.0);
    CHECK(std::min(env_sampling, bsdf) / mis >= 0.5);
}

TEST_CASE("the map is chosen beside the area lights by power, or 1/(N+1) for uniform",
          "[environment]") {
    TempDir dir("mcrt-env");
    const std::string env = write_map(dir, "one.exr", 4, 2, [](int, int, int) { return 1.0f; });
    const auto light = load_environment_light(env, 1.0f, 0.0f, nullptr, nullptr);
    RenderSettings settings = env_settings(env);
    Scene alone = floor_scene(glm::dvec3(0.5), false), beside = floor_scene(glm::dvec3(0.5), true);
    const GpuSceneData no_lights = gpu_scene_for(alone, kCamera, settings);
    const GpuSceneData two_lights = gpu_scene_for(beside, kCamera, settings);
    CHECK(environment_pmf_steps(*light, no_lights, LightSelection::Power) == 1u << 24);
    CHECK(environment_pmf_steps(*light, two_lights, LightSelection::Uniform) ==
          uint32_t(std::round(16777216.0 / 3.0)));
    // A uniform sky of luminance 1 over a scene of radius r = √(6² + 1² + 6²)/2 has power
    // 4π² r²; the two triangles of the hidden light emit 10 × 4 × π.
    const double r2 = (36.0 + 1.0 + 36.0) / 4.0, sky = 4 * kPi * kPi * r2, area = 10.0 * 4.0 * kPi;
    const uint32_t steps = environment_pmf_steps(*light, two_lights, LightSelection::Power);
    CHECK(steps == Approx(16777216.0 * sky / (sky + area)).margin(2.0));
    CHECK(environment_pmf_steps(*light, two_lights, LightSelection::Tree) == steps);
    CHECK(environment_pmf_steps(*light, two_lights, LightSelection::Alias) == steps);
}

TEST_CASE("mcrt render --env refuses hostile maps with one line and exit 2",
          "[environment][hostile]") {
    TempDir dir("mcrt-env");
    // The scene: a floor in a glTF file of its own.
    const std::string scene = dir / "floor.gltf";
    {
        std::ofstream out(scene);
        out << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
            << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
            << R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)"
            << R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIA/"}],)"
            << R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
            << R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
            << R"("min":[0,0,0],"max":[1,0,1]}]})";
    }
    auto hdr = [&](const std::string& name, const std::string& size_line, size_t texels,
                   unsigned char m = 128, unsigned char e = 129) {
        const std::string path = dir / name;
        std::ofstream out(path, std::ios::binary);
        out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" << size_line << "\n";
        for (size_t k = 0; k < texels; ++k) out << m << m << m << e;
        return path;
    };
    auto exr = [&](const std::string& name, float value) {
        return write_map(dir, name, 2, 2, [&](int, int, int) { return value; });
    };
    const std::string truncated_exr =
        write_map(dir, "truncated.exr", 64, 64, [](int, int, int) { return 1.0f; });
    std::filesystem::resize_file(truncated_exr, std::filesystem::file_size(truncated_exr) / 2);
    REQUIRE(::mkfifo((dir / "fifo.hdr").c_str(), 0600) == 0);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {hdr("truncated.hdr", "-Y 4 +X 4", 9), "truncated"},
        {hdr("huge.hdr", "-Y 32768 +X 65536", 1), "65536x32768"},
        {truncated_exr, "cannot read EXR"},
        {exr("nan.exr", NAN), "finite and non-negative"},
        {exr("inf.exr", INFINITY), "finite and non-negative"},
        {exr("negative.exr", -1.0f), "finite and non-negative"},
        {exr("zero.exr", 0.0f), "every texel"},
        {hdr("zero.hdr", "-Y 2 +X 2", 4, 0, 0), "every texel"},
        {dir / "missing.hdr", "no such file"},
        {dir / "fifo.hdr", "FIFO"},
        {exr("named.png", 1.0f), ".exr or .hdr"},
    };
    for (const auto& [path, needle] : cases) {
        const ProcessResult r =
            run_process(MCRT_EXE,
                        {"render", scene, "--env", path, "--width", "8", "--height", "8", "--spp",
                         "4", "--quiet", "--out", dir / "a.exr"},
                        dir.path(), 30);
        INFO(path << ": " << r.err);
        REQUIRE_FALSE(r.timed_out);
        CHECK(r.exit_code == 2);
        CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
        CHECK(r.err.find(path) != std::string::npos);
        CHECK(r.err.find(needle) != std::string::npos);
        CHECK_FALSE(std::filesystem::exists(dir / "a.exr"));
    }
    // A 1 × 1 map is a uniform sky: it renders. --sky with --env is a usage error.
    const std::string one = write_map(dir, "one.exr", 1, 1, [](int, int, int) { return 1.0f; });
    ProcessResult r =
        run_process(MCRT_EXE,
                    {"render", scene, "--env", one, "--width", "8", "--height", "8", "--spp", "4",
                     "--quiet", "--out", dir / "a.exr", "--stats", dir / "a.json"},
                    dir.path(), 60);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    // The stats name the map; without area lights the light strategies choose it always.
    const nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "a.json"));
    CHECK(stats["env"] == one);
    CHECK(stats["env_light_pmf"] == 1.0);
    r = run_process(
        MCRT_EXE, {"render", scene, "--env", one, "--sky", "1", "--quiet", "--out", dir / "b.exr"},
        dir.path(), 30);
    CHECK(r.exit_code == 2);
    CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
}

TEST_CASE(
    "an estimator file written for environment_radiance(scene) is told the call takes the "
    "direction",
    "[environment][estimator-file]") {
    TempDir dir("mcrt-env");
    const std::string file = dir / "old.cl";
    {
        std::ofstream out(file);
        out << "float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
               "                const SampleStream* stream, uint* rays) {\n"
               "    return environment_radiance(scene);\n"
               "}\n";
    }
    const ProcessResult r = run_process(
        MCRT_EXE,
        {"render", scene_path("cornell/CornellBox-Original.gltf"), "--estimator-file", file,
         "--width", "8", "--height", "8", "--spp", "4", "--quiet", "--out", dir / "a.exr"},
        dir.path(), 120);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    const std::vector<std::string> errors = lines_starting_with(r.err, "mcrt: error:");
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find(file + ":3: environment_radiance takes (scene, direction)") !=
          std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "a.exr"));
}

TEST_CASE("an environment map beside punctual lights alone: both are chosen",
          "[environment][punctual][cli]") {
    // A scene lit only by a KHR_lights_punctual light, with a dim uniform map: the map's share
    // of the choice is by power against the punctual light's, never all of it (which would
    // leave the light unseen). The image is the light's, plus the map's albedo × 1e-4.
    TempDir dir;
    const std::string scene = scene_path("punctual/point-light.gltf");
    const std::string map = write_map(dir, "dim.exr", 8, 4, [](int, int, int) { return 1e-4f; });
    auto render_mean = [&](const std::vector<std::string>& extra, const std::string& name,
                           double& variance) {
        std::vector<std::string> args = {"render",  scene,   "--width", "16",          "--height",
                                         "16",      "--spp", "64",      "--estimator", "light-area",
                                         "--quiet", "--out", dir / name};
        args.insert(args.end(), extra.begin(), extra.end());
        const ProcessResult r = run_process(MCRT_EXE, args, dir.path());
        INFO(r.err);
        REQUIRE(r.exit_code == 0);
        const Image image = read_exr(dir / name);
        const double n = double(image.rgb.size());
        double sum = 0.0;
        variance = 0.0;
        for (size_t k = 0; k < image.rgb.size(); ++k) {
            sum += image.rgb[k];
            variance += image.variance[k] / (n * n);
        }
        return sum / n;
    };
    double var_light = 0.0, var_both = 0.0;
    const double light = render_mean({}, "light.exr", var_light);
    const double both = render_mean({"--env", map}, "both.exr", var_both);
    INFO("light alone " << light << ", with the map " << both);
    REQUIRE(light > 1e-2);  // the light is seen: the comparison can fail
    CHECK(std::abs(both - light) <= 4.5 * std::sqrt(var_light + var_both) + 1e-4);
}
