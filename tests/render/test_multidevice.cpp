// One render across several OpenCL devices: POCL_DEVICES="pthread basic" gives two PoCL devices
// on the same cores. The image must be bitwise identical to one device's, survive a device
// fault, and stop cleanly on a time limit or a signal.
#include <catch2/catch.hpp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "image/image.h"
#include "independent_renders.h"
#include "process_support.h"
#include "render/renderer.h"
#include "scene/gltf_import.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

// Before PoCL initialises (the first OpenCL call), and inherited by child processes.
const bool two_devices = [] {
    setenv("POCL_DEVICES", "pthread basic", 1);
    unsetenv("MCRT_FAULT_INJECT");
    return true;
}();

struct Devices {
    std::vector<std::unique_ptr<DeviceContext>> owned;
    std::vector<const DeviceContext*> all;
    Devices() {
        for (const DeviceInfo& d : enumerate_devices([](const std::string& w) { WARN(w); })) {
            owned.push_back(std::make_unique<DeviceContext>(d));
            all.push_back(owned.back().get());
        }
        REQUIRE(all.size() >= 2);
    }
};

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

struct Fixture {
    PlaneScene ps;
    RenderSettings settings;
    GpuSceneData data;
    Fixture() {
        settings.width = 48;
        settings.height = 40;
        settings.spp = 200;  // not a multiple of the chunk size
        settings.estimator = "mis";
        Bvh bvh = build_bvh(ps.scene);
        data = make_gpu_scene(ps.scene, bvh, ps.camera, settings.width, settings.height);
    }
};

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

std::vector<std::string> warnings;
void collect_warning(const std::string& w) { warnings.push_back(w); }

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

}  // namespace

TEST_CASE("two devices render the image of one device, bit for bit, both doing work",
          "[multidevice]") {
    Devices devices;
    Fixture f;
    // Independent samples (one replicate) and Sobol split into 8 replicates (200 = 8 · 25).
    auto [sampler, replicates] =
        GENERATE(std::make_pair("independent", 1u), std::make_pair("sobol", 8u));
    f.settings.sampler = sampler;
    f.settings.replicates = replicates;
    INFO(sampler << ", " << replicates << " replicate(s)");
    RenderResult one =
        render(std::vector<const DeviceContext*>{devices.all[0]}, f.data, f.settings);
    RenderResult other =
        render(std::vector<const DeviceContext*>{devices.all[1]}, f.data, f.settings);
    RenderResult both = render(devices.all, f.data, f.settings);
    CHECK(same_bits(one.image.rgb, both.image.rgb));
    CHECK(same_bits(one.image.variance, both.image.variance));
    CHECK(same_bits(one.image.rgb, other.image.rgb));
    CHECK(both.spp == f.settings.spp);
    REQUIRE(both.devices.size() == 2);
    uint64_t total = 0;
    for (const DeviceReport& d : both.devices) {
        INFO(d.name << ": " << d.samples << " samples in " << d.batches << " batches");
        CHECK(d.samples > 0);
        total += d.samples;
    }
    CHECK(total == uint64_t(f.settings.width) * f.settings.height * f.settings.spp);
    // A fixed --batch, splitting the work differently again, gives the same image too.
    f.settings.batch = 48;
    RenderResult fixed = render(devices.all, f.data, f.settings);
    CHECK(same_bits(one.image.rgb, fixed.image.rgb));
    CHECK(same_bits(one.image.variance, fixed.image.variance));
    CHECK(fixed.replicates == replicates);
}

TEST_CASE("paths of depth 8 render bit for bit alike on one device or two and in any batch",
          "[multidevice][paths]") {
    Devices devices;
    Scene scene = load_gltf(kCornell, [](const std::string&) {});
    RenderSettings settings = image_settings(24, 24, 48);
    settings.max_depth = 8;
    settings.rr_depth = 3;
    GpuSceneData data = make_gpu_scene(scene, build_bvh(scene), scene.cameras.front(),
                                       settings.width, settings.height);
    for (const char* estimator : {"mis", "light-area", "hemisphere-cosine"})
        for (const char* sampler : {"independent", "sobol"}) {
            settings.estimator = estimator;
            settings.sampler = sampler;
            settings.replicates = resolve_replicates(0, settings);
            settings.batch = 0;
            INFO(estimator << " / " << sampler);
            RenderResult one =
                render(std::vector<const DeviceContext*>{devices.all[0]}, data, settings);
            RenderResult other =
                render(std::vector<const DeviceContext*>{devices.all[1]}, data, settings);
            RenderResult both = render(devices.all, data, settings);
            settings.batch = 16;
            RenderResult batched = render(devices.all, data, settings);
            CHECK(same_bits(one.image.rgb, other.image.rgb));
            CHECK(same_bits(one.image.rgb, both.image.rgb));
            CHECK(same_bits(one.image.variance, both.image.variance));
            CHECK(same_bits(one.image.rgb, batched.image.rgb));
            CHECK(same_bits(one.image.variance, batched.image.variance));
            CHECK(one.rays == batched.rays);
            CHECK(one.path_vertices == batched.path_vertices);
            CHECK(one.roulette_ends == both.roulette_ends);
            CHECK(one.roulette_ends > 0);
        }
}

TEST_CASE("a device that fails mid-render is retired and the image is unchanged", "[multidevice]") {
    Devices devices;
    Fixture f;
    RenderResult reference =
        render(std::vector<const DeviceContext*>{devices.all[0]}, f.data, f.settings);
    for (int failing : {0, 1}) {
        // Device `failing` fails at its first launch (every device is handed a first launch).
        setenv("MCRT_FAULT_INJECT",
               (std::to_string(devices.all[failing]->info.index) + ":1").c_str(), 1);
        warnings.clear();
        RenderResult r = render(devices.all, f.data, f.settings, {}, {}, collect_warning);
        unsetenv("MCRT_FAULT_INJECT");
        INFO("failing device " << failing);
        CHECK(same_bits(reference.image.rgb, r.image.rgb));
        CHECK(r.spp == f.settings.spp);
        CHECK(r.devices[size_t(failing)].retired);
        CHECK(!r.devices[size_t(1 - failing)].retired);
        REQUIRE(warnings.size() == 1);
        CHECK(warnings[0].find("retired") != std::string::npos);
        CHECK(warnings[0].find("CL_OUT_OF_RESOURCES") != std::string::npos);
    }
}

TEST_CASE("when every device fails the render is a runtime error", "[multidevice]") {
    Devices devices;
    Fixture f;
    setenv("MCRT_FAULT_INJECT", (std::to_string(devices.all[0]->info.index) + ":1").c_str(), 1);
    CHECK_THROWS_AS(render(std::vector<const DeviceContext*>{devices.all[0]}, f.data, f.settings),
                    RuntimeError);
    unsetenv("MCRT_FAULT_INJECT");
}

TEST_CASE("the command line renders on all devices and reports each one", "[multidevice][cli]") {
    TempDir dir;
    std::vector<std::string> common = {"render", kCornell, "--width", "40",     "--height",
                                       "32",     "--spp",  "48",      "--quiet"};
    auto with = [&](const std::vector<std::string>& extra) { return concat(common, extra); };
    ProcessResult one =
        run_process(MCRT_EXE, with({"--out", dir / "one.exr", "--device", "0"}), dir.path());
    ProcessResult all = run_process(
        MCRT_EXE, with({"--out", dir / "all.exr", "--device", "all", "--stats", dir / "all.json"}),
        dir.path());
    REQUIRE(one.exit_code == 0);
    REQUIRE(all.exit_code == 0);
    Image a = read_exr(dir / "one.exr"), b = read_exr(dir / "all.exr");
    CHECK(same_bits(a.rgb, b.rgb));
    nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "all.json"));
    REQUIRE(stats["devices"].size() == 2);
    for (const auto& d : stats["devices"]) {
        CHECK(d["samples"].get<uint64_t>() > 0);
        CHECK(d.contains("batches"));
        CHECK(d.contains("seconds_busy"));
        CHECK(d.contains("samples_per_second"));
    }
    // With the fault switch the command still succeeds, with one warning line.
    setenv("MCRT_FAULT_INJECT", "1:1", 1);
    ProcessResult faulty =
        run_process(MCRT_EXE, with({"--out", dir / "faulty.exr", "--device", "all"}), dir.path());
    unsetenv("MCRT_FAULT_INJECT");
    REQUIRE(faulty.exit_code == 0);
    CHECK(lines_starting_with(faulty.err, "mcrt: warning:").size() == 1);
    CHECK(same_bits(a.rgb, read_exr(dir / "faulty.exr").rgb));
}

TEST_CASE("a time limit or SIGINT writes a valid partial image of whole chunks",
          "[multidevice][cli]") {
    TempDir dir;
    for (int how : {0, 1}) {
        std::string exr = dir / ("partial" + std::to_string(how) + ".exr");
        std::vector<std::string> args = {
            "render", kCornell,  "--width",           "64",      "--height",
            "64",     "--spp",   "1000000",           "--quiet", "--out",
            exr,      "--stats", dir / "partial.json"};
        ProcessResult r;
        if (how == 0) {
            args.insert(args.end(), {"--time-limit", "1.5"});
            r = run_process(MCRT_EXE, args, dir.path(), 60);
        } else {
            r = run_process(MCRT_EXE, args, dir.path(), 60, SIGINT, 2.0);
        }
        INFO((how == 0 ? "time limit" : "SIGINT") << "; stderr: " << r.err);
        REQUIRE(r.exit_code == 0);
        CHECK(r.seconds < 30);
        Image img = read_exr(exr);
        nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "partial.json"));
        uint32_t spp = stats["spp"].get<uint32_t>();
        CHECK(img.spp == spp);
        CHECK(spp > 0);
        CHECK(spp < 1000000u);
        CHECK(spp % 16 == 0);
        CHECK(stats["stopped_by"] == (how == 0 ? "time limit" : "interrupt"));
        for (float v : img.rgb) REQUIRE(std::isfinite(v));
        // The first spp samples of a longer render are those of a render of spp samples
        // (independent sampler): the partial image is exactly that render.
        std::string full = dir / "full.exr";
        ProcessResult again = run_process(MCRT_EXE,
                                          {"render", kCornell, "--width", "64", "--height", "64",
                                           "--spp", std::to_string(spp), "--quiet", "--out", full},
                                          dir.path(), 120);
        REQUIRE(again.exit_code == 0);
        CHECK(same_bits(img.rgb, read_exr(full).rgb));
    }
}

// With an environment variable set for one child process only.
struct ScopedEnv {
    std::vector<std::string> names;
    ScopedEnv(std::initializer_list<std::pair<const char*, const char*>> vars) {
        for (const auto& [name, value] : vars) setenv(name, value, 1), names.emplace_back(name);
    }
    ~ScopedEnv() {
        for (const std::string& name : names) unsetenv(name.c_str());
    }
};

TEST_CASE("a device that computes wrong values is retired before its samples enter the image",
          "[multidevice][cli][agreement]") {
    TempDir dir;
    const std::vector<std::string> common = {"render",      kCornell, "--width", "40",
                                             "--height",    "32",     "--spp",   "48",
                                             "--estimator", "mis",    "--quiet"};
    auto with = [&](const std::vector<std::string>& extra) { return concat(common, extra); };
    ProcessResult one =
        run_process(MCRT_EXE, with({"--out", dir / "one.exr", "--device", "0"}), dir.path());
    REQUIRE(one.exit_code == 0);
    const Image reference = read_exr(dir / "one.exr");
    // The hook scales every sample of the named device by 1 + 2^-20: the 64 agreement pixels
    // differ, so the device is retired with one warning and the image is device 0's alone.
    ScopedEnv wrong({{"MCRT_TEST_WRONG_DEVICE", "1"}});
    ProcessResult r = run_process(
        MCRT_EXE, with({"--out", dir / "all.exr", "--device", "all", "--stats", dir / "all.json"}),
        dir.path());
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    std::vector<std::string> warnings = lines_starting_with(r.err, "mcrt: warning:");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("device 1") != std::string::npos);
    CHECK(warnings[0].find("disagrees with device 0") != std::string::npos);
    CHECK(warnings[0].find(" against ") != std::string::npos);  // the first differing values
    CHECK(same_bits(reference.rgb, read_exr(dir / "all.exr").rgb));
    CHECK(same_bits(reference.variance, read_exr(dir / "all.exr").variance));
    nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "all.json"));
    REQUIRE(stats["devices"].size() == 2);
    CHECK(stats["devices"][1]["samples"].get<uint64_t>() == 0);
}

TEST_CASE("a device whose compiler crashes is retired with one line; with none left, exit 1",
          "[multidevice][cli][agreement]") {
    TempDir dir;
    // PoCL's builds run in a child process (as other drivers' do) when its own cache is off,
    // and the hook makes the child for device 1 die of SIGSEGV.
    ScopedEnv env({{"POCL_KERNEL_CACHE", "0"},
                   {"MCRT_NO_KERNEL_CACHE", "1"},
                   {"MCRT_TEST_COMPILER_CRASH", "1"}});
    const std::vector<std::string> common = {"render", kCornell, "--width", "32",     "--height",
                                             "32",     "--spp",  "16",      "--quiet"};
    auto with = [&](const std::vector<std::string>& extra) { return concat(common, extra); };
    ProcessResult one =
        run_process(MCRT_EXE, with({"--out", dir / "one.exr", "--device", "0"}), dir.path());
    REQUIRE(one.exit_code == 0);
    ProcessResult all =
        run_process(MCRT_EXE, with({"--out", dir / "all.exr", "--device", "all"}), dir.path());
    INFO("stderr: " << all.err);
    REQUIRE(all.exit_code == 0);
    std::vector<std::string> warnings = lines_starting_with(all.err, "mcrt: warning:");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("device 1") != std::string::npos);
    CHECK(warnings[0].find("SIGSEGV") != std::string::npos);
    CHECK(warnings[0].find("-D MCRT_ESTIMATE=") != std::string::npos);  // the variant
    CHECK(same_bits(read_exr(dir / "one.exr").rgb, read_exr(dir / "all.exr").rgb));

    ProcessResult alone =
        run_process(MCRT_EXE, with({"--out", dir / "alone.exr", "--device", "1"}), dir.path());
    INFO("stderr: " << alone.err);
    CHECK(alone.exit_code == 1);
    CHECK(lines_starting_with(alone.err, "mcrt: error:").size() == 1);
    CHECK(alone.err.find("SIGSEGV") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "alone.exr"));
}
