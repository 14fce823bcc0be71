// Users' estimators (--estimator-file, docs/ESTIMATORS.md): the example re-implementing
// light-area through the public API renders the built-in's image bit for bit; build errors name
// the user's FILE:LINE with exit 2 and write nothing; every example in examples/estimators is
// unbiased on the analytic plane scene (error bars from independent renders, as the built-ins).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>

#include "analytic_scenes.h"
#include "device_support.h"
#include "example_estimators.h"
#include "image/image.h"
#include "independent_renders.h"
#include "process_support.h"
#include "render/variants.h"
#include "scene/gltf_import.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";
const std::string kLightArea = std::string(MCRT_EXAMPLES) + "/estimators/light_area.cl";

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

ProcessResult run_mcrt(const TempDir& tmp, const std::vector<std::string>& args) {
    ProcessResult r = run_process(MCRT_EXE, args, tmp.path(), 120.0);
    INFO("mcrt " << args.front() << "...: exit " << r.exit_code << "\n  stderr: " << r.err);
    CHECK_FALSE(r.timed_out);
    return r;
}

}  // namespace

TEST_CASE("examples/estimators/light_area.cl renders light-area's image bit for bit",
          "[estimator-file][cli]") {
    TempDir tmp("mcrt-estimator-file");
    for (const char* sampler : {"independent", "sobol", "stratified"})
        for (const char* select : {"power", "uniform"}) {
            std::vector<std::string> common = {
                kCornell, "--width",   "40",    "--height",       "32",   "--spp",  "48", "--seed",
                "11",     "--sampler", sampler, "--light-select", select, "--quiet"};
            std::vector<std::string> builtin = {"render", "--out", tmp / "builtin.exr",
                                                "--estimator", "light-area"};
            std::vector<std::string> file = {"render", "--out", tmp / "file.exr",
                                             "--estimator-file", kLightArea};
            builtin.insert(builtin.end(), common.begin(), common.end());
            file.insert(file.end(), common.begin(), common.end());
            INFO(sampler << " / " << select);
            REQUIRE(run_mcrt(tmp, builtin).exit_code == 0);
            REQUIRE(run_mcrt(tmp, file).exit_code == 0);
            Image a = read_exr(tmp / "builtin.exr"), b = read_exr(tmp / "file.exr");
            double sum = 0;
            for (float v : a.rgb) sum += v;
            CHECK(sum > 0);  // not two black images
            CHECK(same_bits(a.rgb, b.rgb));
            CHECK(same_bits(a.variance, b.variance));
        }
}

TEST_CASE("an estimator file sees punctual lights through the light strategies: light-area's image",
          "[estimator-file][cli][punctual]") {
    // sample_light_area chooses point, spot and directional lights beside the area light, so
    // the example draws them as the built-in does, on every selection.
    TempDir tmp("mcrt-estimator-file");
    const std::string scene = std::string(MCRT_SCENES) + "/punctual/punctual-lights.gltf";
    for (const char* select : {"power", "tree"}) {
        std::vector<std::string> common = {
            scene, "--width",        "40",   "--height",    "32", "--spp",  "16", "--seed",
            "5",   "--light-select", select, "--max-depth", "2",  "--quiet"};
        std::vector<std::string> builtin = {"render", "--out", tmp / "builtin.exr", "--estimator",
                                            "light-area"};
        std::vector<std::string> file = {"render", "--out", tmp / "file.exr", "--estimator-file",
                                         kLightArea};
        builtin.insert(builtin.end(), common.begin(), common.end());
        file.insert(file.end(), common.begin(), common.end());
        INFO(select);
        REQUIRE(run_mcrt(tmp, builtin).exit_code == 0);
        REQUIRE(run_mcrt(tmp, file).exit_code == 0);
        Image a = read_exr(tmp / "builtin.exr"), b = read_exr(tmp / "file.exr");
        double sum = 0;
        for (float v : a.rgb) sum += v;
        CHECK(sum > 0);
        CHECK(same_bits(a.rgb, b.rgb));
        CHECK(same_bits(a.variance, b.variance));
    }
}

TEST_CASE(
    "examples/estimators/bsdf_directions.cl renders bsdf's image bit for bit on glossy and "
    "Lambertian surfaces, and under the sky light",
    "[estimator-file][cli][materials]") {
    TempDir tmp("mcrt-estimator-file");
    const std::string example = std::string(MCRT_EXAMPLES) + "/estimators/bsdf_directions.cl";
    const std::string dielectric = std::string(MCRT_SCENES) + "/glossy/dielectric-plane.gltf";
    struct Case {
        std::string scene;
        const char* materials;
        const char* sky;  // "0": no sky light
    };
    // The Cornell box's open front lets BSDF directions escape: with --sky they see the sky
    // light, which the built-in counts and the file must too.
    std::vector<Case> cases = {{dielectric, "gltf", "0"},
                               {dielectric, "lambert", "0"},
                               {kCornell, "gltf", "0"},
                               {kCornell, "lambert", "0"},
                               {kCornell, "lambert", "0.5"}};
    for (const Case& c : cases) {
        const std::string& scene = c.scene;
        const char* materials = c.materials;
        {
            std::vector<std::string> common = {
                scene,    "--width", "32",        "--height", "32",          "--spp",   "32",
                "--seed", "3",       "--sampler", "sobol",    "--materials", materials, "--quiet"};
            if (std::string(c.sky) != "0") common.insert(common.end(), {"--sky", c.sky});
            std::vector<std::string> builtin = {"render", "--out", tmp / "builtin.exr",
                                                "--estimator", "bsdf"};
            std::vector<std::string> file = {"render", "--out", tmp / "file.exr",
                                             "--estimator-file", example};
            builtin.insert(builtin.end(), common.begin(), common.end());
            file.insert(file.end(), common.begin(), common.end());
            INFO(scene << " / " << materials << " / sky " << c.sky);
            REQUIRE(run_mcrt(tmp, builtin).exit_code == 0);
            REQUIRE(run_mcrt(tmp, file).exit_code == 0);
            Image a = read_exr(tmp / "builtin.exr"), b = read_exr(tmp / "file.exr");
            double sum = 0;
            for (float v : a.rgb) sum += v;
            CHECK(sum > 0);
            CHECK(same_bits(a.rgb, b.rgb));
        }
    }
}

TEST_CASE("an estimator file is called at every vertex of a path: light-area's image bit for bit",
          "[estimator-file][cli][paths]") {
    // Depth 6 with roulette and the sky light through the Cornell box's open front: the file's
    // light strategy samples the sky as the built-in's does, at every vertex with its numbers.
    TempDir tmp("mcrt-estimator-file-paths");
    for (const char* sampler : {"independent", "sobol"}) {
        std::vector<std::string> common = {
            kCornell, "--width",     "32", "--height",   "24", "--spp", "32",  "--sampler",
            sampler,  "--max-depth", "6",  "--rr-depth", "2",  "--sky", "0.3", "--quiet"};
        std::vector<std::string> builtin = {"render", "--out", tmp / "builtin.exr", "--estimator",
                                            "light-area"};
        std::vector<std::string> file = {"render", "--out", tmp / "file.exr", "--estimator-file",
                                         kLightArea};
        builtin.insert(builtin.end(), common.begin(), common.end());
        file.insert(file.end(), common.begin(), common.end());
        INFO(sampler);
        REQUIRE(run_mcrt(tmp, builtin).exit_code == 0);
        REQUIRE(run_mcrt(tmp, file).exit_code == 0);
        Image a = read_exr(tmp / "builtin.exr"), b = read_exr(tmp / "file.exr");
        CHECK(same_bits(a.rgb, b.rgb));
        CHECK(same_bits(a.variance, b.variance));
    }
}

TEST_CASE("a build error in an estimator file names FILE:LINE, exits 2 and writes nothing",
          "[estimator-file][cli]") {
    TempDir tmp("mcrt-estimator-file");
    const std::string file = tmp / "broken.cl";
    std::ofstream(file) << "/* a user's estimator with an error on line 3 */\n"
                           "float3 estimate(const SceneView* scene, const SurfacePoint* sp, "
                           "const SampleStream* stream, uint* rays) {\n"
                           "    return not_declared_anywhere * sp->n;\n"
                           "}\n";
    const std::string out = tmp / "x.exr";
    ProcessResult r = run_mcrt(
        tmp, {"render", kCornell, "--out", out, "--png", tmp / "x.png", "--stats", tmp / "x.json",
              "--estimator-file", file, "--width", "8", "--height", "8", "--quiet"});
    CHECK(r.exit_code == 2);
    // One error line, naming the file and line; the build log follows it.
    size_t first = r.err.find("mcrt: error: ");
    REQUIRE(first != std::string::npos);
    CHECK(r.err.find("mcrt: error: ", first + 1) == std::string::npos);
    std::string line = r.err.substr(first, r.err.find('\n', first) - first);
    INFO(line);
    CHECK(line.find(file + ":3") != std::string::npos);
    CHECK(line.find("not_declared_anywhere") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(out));
    CHECK_FALSE(std::filesystem::exists(tmp / "x.png"));
    CHECK_FALSE(std::filesystem::exists(tmp / "x.json"));
}

TEST_CASE("estimator files that cannot be used are refused with exit 2", "[estimator-file][cli]") {
    TempDir tmp("mcrt-estimator-file");
    std::vector<std::string> base = {"render", kCornell, "--out", tmp / "x.exr", "--quiet"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = base;
        a.insert(a.end(), extra.begin(), extra.end());
        return a;
    };
    ProcessResult missing = run_mcrt(tmp, with({"--estimator-file", tmp / "nope.cl"}));
    CHECK(missing.exit_code == 2);
    CHECK(missing.err.find("nope.cl") != std::string::npos);
    ProcessResult directory = run_mcrt(tmp, with({"--estimator-file", tmp.path().string()}));
    CHECK(directory.exit_code == 2);
    CHECK(directory.err.find("not a regular file") != std::string::npos);
    ProcessResult both =
        run_mcrt(tmp, with({"--estimator-file", kLightArea, "--estimator", "mis"}));
    CHECK(both.exit_code == 2);
    // A file that defines no `estimate` is refused before any build, naming the function.
    std::ofstream(tmp / "empty.cl") << "/* nothing */\n";
    ProcessResult empty = run_mcrt(tmp, with({"--estimator-file", tmp / "empty.cl"}));
    CHECK(empty.exit_code == 2);
    CHECK(empty.err.find("defines no function float3 estimate") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(tmp / "x.exr"));
}

TEST_CASE("every example estimator counts the sky light: under --sky its mean is light-area's",
          "[estimator-file][estimators][sky]") {
    // The Cornell box's open front lets the sky light in: a file that ignored it (as
    // light_contribution.cl and bsdf_directions.cl once did) would miss by far more than its
    // error bar, which the second check makes sure of.
    DeviceContext device = first_device();
    Scene scene = load_gltf(kCornell, nullptr);
    RenderSettings settings = image_settings(16, 16, 64);
    settings.sky = glm::vec3(0.5f);
    settings.sky_light = true;
    GpuSceneData data = gpu_scene_for(scene, scene.cameras.front(), settings);
    RenderSettings builtin = settings;
    builtin.estimator = "light-area";
    Renders with_sky = independent_renders(device, data, builtin, 10, 500);
    builtin.sky_light = false;
    Renders without = independent_renders(device, data, builtin, 10, 500);
    for (const std::string& file : example_estimator_files()) {
        RenderSettings s = settings;
        use_estimator_file(s, file);
        // Files that sample no light find the small ceiling light by their directions alone.
        if (s.estimator_source.find("sample_light") == std::string::npos) s.spp = 256;
        Renders r = independent_renders(device, data, s, 10, 700);
        INFO(file << ": mean (" << r.mean.x << ", " << r.mean.y << ", " << r.mean.z
                  << "), light-area's (" << with_sky.mean.x << ", " << with_sky.mean.y << ", "
                  << with_sky.mean.z << "), without the sky (" << without.mean.x << ", "
                  << without.mean.y << ", " << without.mean.z << ")");
        CHECK(r.nan_samples == 0);
        CHECK(r.non_finite_pixels == 0);
        for (int c = 0; c < 3; ++c) {
            double se = std::hypot(r.standard_error[c], with_sky.standard_error[c]);
            CHECK(std::abs(r.mean[c] - with_sky.mean[c]) <= 4.5 * se);
            CHECK(with_sky.mean[c] - without.mean[c] > 10.0 * se);  // the check has power
        }
    }
}

TEST_CASE("every example estimator is unbiased on a polygon light over a plane",
          "[estimator-file][estimators][analytic]") {
    DeviceContext device = first_device();
    PlaneScene ps;
    RenderSettings settings = image_settings(16, 16, 64);
    GpuSceneData data = gpu_scene_for(ps.scene, ps.camera, settings);
    glm::dvec3 exact = image_mean(ps.exact_image(settings.width, settings.height));
    const std::vector<std::string> files = example_estimator_files();
    REQUIRE(files.size() >= 2);
    for (const std::string& file : files)
        for (const std::string& select : variant_names(kLightSelectVariants))
            for (const std::string& sampler : variant_names(kSamplerVariants)) {
                use_estimator_file(settings, file);
                settings.light_select = select;
                settings.sampler = sampler;
                Renders r = independent_renders(device, data, settings, 10, 1000);
                check_unbiased(r, exact, file + " / " + select + " / " + sampler);
                CHECK(r.non_finite_pixels == 0);
                CHECK(r.standard_error.x < 0.05 * exact.x);  // not vacuous
            }
}

namespace {

const std::string kEstimateBody =
    "float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream,\n"
    "                uint* rays) {\n"
    "    return (float3)(0.25f);\n"
    "}\n";

// `mcrt render` of the Cornell box with the estimator file `text`: exit 2 and exactly one
// `mcrt: error:` line, which names FILE:LINE (or FILE alone when line is 0) and says `says`;
// nothing written. Returns that line.
std::string refused(const TempDir& tmp, const std::string& text, int line,
                    const std::string& says) {
    const std::string file = tmp / "user.cl";
    std::ofstream(file, std::ios::binary) << text;
    const std::string out = tmp / "x.exr";
    ProcessResult r = run_mcrt(tmp, {"render", kCornell, "--out", out, "--estimator-file", file,
                                     "--width", "8", "--height", "8", "--spp", "4", "--quiet"});
    CHECK(r.exit_code == 2);
    size_t first = r.err.find("mcrt: error: ");
    REQUIRE(first != std::string::npos);
    CHECK(r.err.find("mcrt: error: ", first + 1) == std::string::npos);
    std::string error = r.err.substr(first, r.err.find('\n', first) - first);
    INFO(error);
    const std::string where = line > 0 ? file + ":" + std::to_string(line) + ": " : file;
    CHECK(error.find(where) != std::string::npos);
    CHECK(error.find(says) != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(out));
    return error;
}

}  // namespace

TEST_CASE("an estimator file's includes other than \"api.cl\" are refused before any compiler runs",
          "[estimator-file][cli][hostile]") {
    TempDir tmp("mcrt-estimator-include");
    // A path that exists nowhere: a compiler would say "file not found"; the check says why.
    const std::string only = "may include only \"api.cl\"";
    refused(tmp, "/* 1 */\n#include </nonexistent-mcrt/passwd>\n" + kEstimateBody, 2, only);
    refused(tmp, "#define F \"/etc/passwd\"\n#include F\n" + kEstimateBody, 2, only);
    // With MCRT_KERNEL_DIR set, mcrt's kernels come from disk; the user's path still goes nowhere.
    setenv("MCRT_KERNEL_DIR", (std::string(MCRT_SOURCE_DIR) + "/kernels").c_str(), 1);
    refused(tmp, "#include \"../../../etc/passwd\"\n" + kEstimateBody, 1, only);
    unsetenv("MCRT_KERNEL_DIR");
    refused(tmp, "\n\n#line 1 \"render.cl\"\n" + kEstimateBody, 3, "#line");
}

TEST_CASE("includes in comments and inactive regions are ignored and the file renders its image",
          "[estimator-file][cli]") {
    TempDir tmp("mcrt-estimator-include");
    const std::string file = tmp / "commented.cl";
    std::ofstream(file) << "// #include </etc/passwd>\n/* #include </etc/passwd> */\n#if 0\n"
                           "#include </etc/passwd>\n#endif\n#include \"api.cl\"\n"
                        << kEstimateBody;
    const std::string plain = tmp / "plain.cl";
    std::ofstream(plain) << kEstimateBody;
    std::vector<std::string> common = {kCornell, "--width", "8",       "--height",        "8",
                                       "--spp",  "4",       "--quiet", "--estimator-file"};
    std::vector<std::string> a = {"render", "--out", tmp / "a.exr"},
                             b = {"render", "--out", tmp / "b.exr"};
    a.insert(a.end(), common.begin(), common.end());
    b.insert(b.end(), common.begin(), common.end());
    a.push_back(file);
    b.push_back(plain);
    REQUIRE(run_mcrt(tmp, a).exit_code == 0);
    REQUIRE(run_mcrt(tmp, b).exit_code == 0);
    Image x = read_exr(tmp / "a.exr"), y = read_exr(tmp / "b.exr");
    CHECK(x.rgb[0] > 0.0f);
    CHECK(same_bits(x.rgb, y.rgb));
}

TEST_CASE("hostile estimator files are refused with one line naming the file's line, exit 2",
          "[estimator-file][cli][hostile]") {
    TempDir tmp("mcrt-estimator-hostile");
    refused(tmp, kEstimateBody + std::string("/* a NUL */\0\n", 13), 5, "contains a NUL byte");
    refused(tmp, "/* float3 estimate(int x) { } */\nfloat f(void) { return 0.0f; }\n", 0,
            "defines no function float3 estimate");
    refused(tmp, kEstimateBody + "kernel void render(global float* x) { }\n", 5,
            "defines the kernel 'render'");
    refused(tmp, "float g(int n) {\n    return n > 0 ? g(n - 1) : 0.0f;\n}\n" + kEstimateBody, 2,
            "'g' calls itself: OpenCL C forbids recursion");
    refused(tmp,
            "float h(int n);\nfloat g(int n) { return h(n); }\n"
            "float h(int n) { return n > 0 ? g(n - 1) : 0.0f; }\n" +
                kEstimateBody,
            2, "'g' calls itself (through h)");
    refused(tmp,
            "float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
            "                const SampleStream* stream, uint* rays) {\n"
            "    float big[4194304];\n    big[*rays] = 1.0f;\n    return (float3)(big[3]);\n}\n",
            3, "private arrays of 16777216 bytes");
}

TEST_CASE("a name the estimator file shares with mcrt's kernels is reported at the file's line",
          "[estimator-file][cli]") {
    // The compiler reports the conflict in render.cl (PoCL prints no note naming the first
    // definition); the error names the user's line.
    TempDir tmp("mcrt-estimator-redefinition");
    refused(tmp, kEstimateBody + "\nfloat render(int x) { return 1.0f; }\n", 6,
            "mcrt's kernels already define 'render'");
}
