// One image whatever implementation renders it: with two OpenCL implementations present (PoCL
// and Intel's CPU runtime under scripts/with-intel, as .ci/run runs this), each one's EXR and
// that of --device all over both are the same bytes, for the determinism configurations. With
// one implementation the cases skip.
#include <catch2/catch.hpp>
#include <map>
#include <nlohmann/json.hpp>

#include "cl/device.h"
#include "image/image.h"
#include "process_support.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";
const std::string kGlossy = std::string(MCRT_SCENES) + "/glossy/cornell-metal-block.gltf";
const std::string kVeach = std::string(MCRT_SCENES) + "/veach-mis/veach-mis.gltf";
const std::string kTextured = std::string(MCRT_TEST_DATA) + "/textured/";

// The first device of each platform, by index, keyed by platform name.
std::map<std::string, int> one_device_per_platform() {
    std::map<std::string, int> first;
    for (const DeviceInfo& d : enumerate_devices([](const std::string& w) { WARN(w); }))
        first.emplace(d.platform_name, d.index);
    return first;
}

struct Configuration {
    const char* name;
    std::string scene;
    std::vector<std::string> options;
};

}  // namespace

TEST_CASE("every OpenCL implementation renders the same bytes, alone and together",
          "[vendors][determinism]") {
    const std::map<std::string, int> platforms = one_device_per_platform();
    if (platforms.size() < 2)
        skip_test("one OpenCL implementation present (run under scripts/with-intel for two)");
    // An environment map of a dim sky and a few bright texels (a sun), for the map's lookup and
    // its texel sampling (kernels/lights/environment.cl).
    TempDir maps;
    Image map(32, 16);
    for (size_t k = 0; k < map.rgb.size(); ++k) map.rgb[k] = (k / 3) % 97 < 2 ? 500.0f : 0.4f;
    const std::string sun = maps / "sun.exr";
    write_exr(sun, map);
    const std::string scenes = std::string(MCRT_SCENES);
    const std::vector<Configuration> configurations = {
        {"direct light-area", kCornell, {"--estimator", "light-area"}},
        {"glossy mis", kGlossy, {"--estimator", "mis", "--materials", "gltf"}},
        {"Sobol mis on veach-mis", kVeach, {"--estimator", "mis", "--sampler", "sobol"}},
        {"depth-8 paths", kCornell, {"--estimator", "mis", "--max-depth", "8"}},
        {"light tree, ambient sky",
         kCornell,
         {"--estimator", "light-solid-angle", "--light-select", "tree", "--sky", "0.3"}},
        {"bilinear texture", kTextured + "checker_linear.gltf", {"--estimator", "mis"}},
        {"masked occluder", kTextured + "mask_occluder.gltf", {"--estimator", "light-area"}},
        {"blended light, depth 3",
         kTextured + "blend_texture_light.gltf",
         {"--estimator", "mis", "--max-depth", "3"}},
        {"environment map, mis depth 3",
         scenes + "/env/sun-blocks.gltf",
         {"--estimator", "mis", "--max-depth", "3", "--env", sun, "--env-rotate", "30"}},
        {"environment map, light-solid-angle beside area lights",
         kCornell,
         {"--estimator", "light-solid-angle", "--light-select", "tree", "--env", sun}},
        {"punctual lights, light tree, depth 2",
         scenes + "/punctual/punctual-lights.gltf",
         {"--estimator", "mis", "--light-select", "tree", "--max-depth", "2"}},
        {"glass, depth 6",
         scenes + "/glass/glass-sphere.gltf",
         {"--estimator", "mis", "--max-depth", "6"}},
    };
    TempDir dir;
    for (const Configuration& c : configurations) {
        DYNAMIC_SECTION(c.name) {
            std::vector<std::string> common = {"render", c.scene, "--width", "40",     "--height",
                                               "32",     "--spp", "48",      "--quiet"};
            common.insert(common.end(), c.options.begin(), c.options.end());
            auto render = [&](const std::string& device, const std::string& out) {
                std::vector<std::string> args = common;
                args.insert(args.end(), {"--device", device, "--out", dir / out, "--stats",
                                         dir / (out + ".json")});
                ProcessResult r = run_process(MCRT_EXE, args, dir.path(), 600);
                INFO("--device " << device << ": " << r.err);
                REQUIRE(r.exit_code == 0);
                CHECK(lines_starting_with(r.err, "mcrt: warning:").empty());
                return read_whole_file(dir / out);
            };
            std::string reference;
            for (const auto& [platform, index] : platforms) {
                std::string bytes = render(std::to_string(index), "one.exr");
                INFO("platform " << platform);
                if (reference.empty())
                    reference = bytes;
                else
                    CHECK(bytes == reference);
            }
            CHECK(render("all", "all.exr") == reference);
            // Every device took part: none was retired by the agreement check.
            nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "all.exr.json"));
            for (const auto& d : stats["devices"]) CHECK(d["samples"].get<uint64_t>() > 0);
        }
    }
}

TEST_CASE("Intel's runtime refusing its context costs its device alone under --device all",
          "[vendors]") {
    // CL_CONFIG_CPU_TARGET_ARCH=junk: Intel's CPU runtime lists its device, then refuses a
    // context for it (CL_DEVICE_NOT_AVAILABLE); the render goes on with PoCL's device, as it
    // does when a device's compiler crashes.
    const std::map<std::string, int> platforms = one_device_per_platform();
    int intel = -1;
    for (const auto& [name, index] : platforms)
        if (name.find("Intel") != std::string::npos) intel = index;
    if (intel < 0 || platforms.size() < 2)
        skip_test("Intel's runtime beside another implementation is needed (scripts/with-intel)");
    TempDir dir;
    auto args = [&](const std::string& out, const std::string& device) {
        return std::vector<std::string>{"render", kCornell,   "--width", "24",      "--height",
                                        "16",     "--spp",    "16",      "--quiet", "--out",
                                        out,      "--device", device};
    };
    int other = -1;
    for (const auto& [name, index] : platforms)
        if (index != intel) other = index;
    const ProcessResult reference =
        run_process(MCRT_EXE, args(dir / "b.exr", std::to_string(other)), dir.path(), 300);
    setenv("CL_CONFIG_CPU_TARGET_ARCH", "junk", 1);
    const ProcessResult all = run_process(MCRT_EXE, args(dir / "a.exr", "all"), dir.path(), 300);
    unsetenv("CL_CONFIG_CPU_TARGET_ARCH");
    INFO(reference.err << all.err);
    REQUIRE(reference.exit_code == 0);
    CHECK(all.exit_code == 0);
    const std::vector<std::string> warnings = lines_starting_with(all.err, "mcrt: warning:");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("skipping device " + std::to_string(intel)) != std::string::npos);
    CHECK(warnings[0].find("clCreateContext failed") != std::string::npos);
    CHECK(read_whole_file(dir / "a.exr") == read_whole_file(dir / "b.exr"));
}
