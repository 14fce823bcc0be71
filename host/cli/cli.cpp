#include "cli/cli.h"

#include <array>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bench/bench.h"
#include "bvh/bvh.h"
#include "cl/cl_error.h"
#include "cl/device.h"
#include "cl/no_device.h"
#include "cli/integrate.h"
#include "cli/progress.h"
#include "cli/usage_errors.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/output_paths.h"
#include "common/stop_signals.h"
#include "common/value_limits.h"
#include "image/image.h"
#include "image/image_check.h"
#include "render/memory_estimate.h"
#include "render/renderer.h"
#include "scene/gltf_import.h"

namespace mcrt {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int) { g_interrupted = 1; }

// While a render runs, SIGINT and SIGTERM ask it to stop and write the samples done so far;
// a second signal ends the process at once.
struct InterruptGuard {
    InterruptGuard() {
        g_interrupted = 0;
        struct sigaction action {};
        action.sa_handler = on_interrupt;
        action.sa_flags = SA_RESETHAND;
        sigemptyset(&action.sa_mask);
        sigaction(SIGINT, &action, &old_int);
        sigaction(SIGTERM, &action, &old_term);
    }
    ~InterruptGuard() {
        if (outputs_are_complete()) return;  // stop signals stay ignored: nothing left to save
        sigaction(SIGINT, &old_int, nullptr);
        sigaction(SIGTERM, &old_term, nullptr);
    }
    struct sigaction old_int {}, old_term {};
};

void print_warning(const std::string& message) {
    std::cerr << "mcrt: warning: " << message << std::endl;
}

struct RenderOptions {
    std::string scene, out, png, stats;
    int width = 512, height = 512;
    uint32_t spp = 16;
    std::string estimator = "light-area", light_select = "power", sampler = "independent";
    std::string mis_heuristic = "balance";
    uint32_t seed = 0;
    std::string sky = "1";
    float ao_distance = 0.0f;
    int camera = -1;
    std::vector<std::string> devices;
    uint32_t batch = 0;
    double time_limit = 0.0;
    float exposure = 0.0f;
    bool quiet = false;
};

// CLI11's Range lets NaN through (both comparisons are false): reject non-finite values first.
const CLI::Validator kFinite(
    [](std::string& text) {
        try {
            size_t used = 0;
            double v = std::stod(text, &used);
            if (used == text.size() && std::isfinite(v)) return std::string();
        } catch (const std::exception&) {
        }
        return "'" + text + "' is not a finite number";
    },
    "FINITE");

// Devices named by --device (index, cpu, gpu, all; repeatable), in list order, no duplicates.
std::vector<DeviceInfo> select_devices(const std::vector<std::string>& specs) {
    std::vector<DeviceInfo> all = enumerate_devices(print_warning);
    if (all.empty()) throw RuntimeError(no_device_message());
    if (specs.empty()) return {all.front()};
    std::set<int> chosen;
    for (const std::string& spec : specs) {
        bool matched = false;
        for (const DeviceInfo& d : all) {
            bool match = spec == "all" || (spec == "cpu" && d.type_name() == "cpu") ||
                         (spec == "gpu" && d.type_name() == "gpu") ||
                         spec == std::to_string(d.index);
            if (match) chosen.insert(d.index), matched = true;
        }
        if (!matched) {
            bool numeric = !spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos;
            std::string why = numeric ? "no such device (" + std::to_string(all.size()) +
                                            " found; see `mcrt devices`)"
                                      : "expected a device index, cpu, gpu or all";
            if (spec == "cpu" || spec == "gpu") throw RuntimeError("--device " + spec + ": no " + spec + " device found");
            throw InputError("--device " + spec + ": " + why);
        }
    }
    std::vector<DeviceInfo> result;
    for (int i : chosen) result.push_back(all[size_t(i)]);
    return result;
}

glm::vec3 parse_sky(const std::string& text) {
    std::vector<float> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            size_t used = 0;
            float x = std::stof(item, &used);
            if (used != item.size() || !std::isfinite(x) || x < 0 || x > kMaxRadiance) throw std::invalid_argument(item);
            v.push_back(x);
        } catch (const std::exception&) {
            throw InputError("--sky " + text + ": expected R,G,B or one value, each in [0, 1e15]");
        }
    }
    if (v.size() == 1) return glm::vec3(v[0]);
    if (v.size() == 3) return glm::vec3(v[0], v[1], v[2]);
    throw InputError("--sky " + text + ": expected R,G,B or one value");
}

int run_devices() {
    std::vector<DeviceInfo> devices = enumerate_devices(print_warning);
    if (devices.empty()) throw RuntimeError(no_device_message());
    for (const DeviceInfo& d : devices) {
        std::printf("%d: %s [%s] — %s, %s, %u compute units, %.1f GiB, driver %s\n", d.index,
                    d.name.c_str(), d.type_name().c_str(), d.platform_name.c_str(),
                    d.version.c_str(), d.compute_units, double(d.global_memory) / (1 << 30),
                    d.driver_version.c_str());
    }
    return 0;
}

int run_render(const RenderOptions& o) {
    auto start = std::chrono::steady_clock::now();
    const std::vector<OutputFile> outputs = {{"--out", o.out}, {"--png", o.png}, {"--stats", o.stats}};
    check_outputs(outputs, {o.scene});

    RenderSettings settings;
    settings.width = o.width;
    settings.height = o.height;
    settings.spp = o.spp;
    settings.estimator = o.estimator;
    settings.light_select = o.light_select == "uniform" ? LightSelect::Uniform
                            : o.light_select == "alias" ? LightSelect::Alias
                                                        : LightSelect::Power;
    settings.sampler = o.sampler == "stratified" ? SamplerKind::Stratified
                       : o.sampler == "sobol"    ? SamplerKind::Sobol
                                                 : SamplerKind::Independent;
    settings.mis_heuristic = o.mis_heuristic == "power" ? MisHeuristic::Power : MisHeuristic::Balance;
    settings.sky = parse_sky(o.sky);
    settings.ao_distance = o.ao_distance;
    settings.seed = o.seed;
    settings.batch = o.batch;
    render_program_options(settings);  // rejects what is not supported before any work

    std::vector<std::string> inputs;
    Scene scene = load_gltf(o.scene, print_warning, &inputs);
    check_outputs(outputs, inputs);  // its buffers too
    check_host_memory("a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " render",
                      render_host_bytes(o.width, o.height));
    if (scene.triangle_count() == 0) print_warning(o.scene + ": the scene has no triangles");
    bool ambient = o.estimator.rfind("ambient-", 0) == 0;
    if (!ambient && collect_emitters(scene).empty())
        print_warning(o.scene + ": no emissive triangles: direct lighting is black");
    Camera camera;
    if (o.camera >= 0) {
        if (size_t(o.camera) >= scene.cameras.size())
            throw InputError("--camera " + std::to_string(o.camera) + ": " + o.scene + " has " +
                             std::to_string(scene.cameras.size()) + " perspective camera(s)");
        camera = scene.cameras[size_t(o.camera)];
    } else {
        camera = scene.cameras.empty() ? bench_camera(scene) : scene.cameras.front();
    }

    std::vector<DeviceInfo> devices = select_devices(o.devices);
    std::vector<std::unique_ptr<DeviceContext>> contexts;
    std::vector<const DeviceContext*> device_list;
    for (const DeviceInfo& d : devices) {
        contexts.push_back(std::make_unique<DeviceContext>(d));
        device_list.push_back(contexts.back().get());
    }

    Bvh bvh = build_bvh(scene);
    GpuSceneData gpu_scene = make_gpu_scene(scene, bvh, camera, o.width, o.height);

    RenderControl control;
    control.time_limit = o.time_limit;
    control.interrupted = &g_interrupted;
    InterruptGuard interrupt_guard;  // SIGINT / SIGTERM: stop and write what is done
    ProgressBar bar(!o.quiet, uint64_t(o.width) * o.height);
    RenderResult result = render(
        device_list, gpu_scene, settings,
        [&](uint32_t done, uint32_t total, const std::vector<DeviceReport>& d) {
            bar.update(done, total, d);
        },
        control, print_warning);
    bar.finish();
    if (!result.stopped_by.empty())
        print_warning("stopped by " + result.stopped_by + " after " + std::to_string(result.spp) +
                      " of " + std::to_string(o.spp) + " samples per pixel; writing those");

    if (uint64_t bad = nonfinite_pixels(result.image))
        throw RuntimeError(std::to_string(bad) + " pixels are not finite (radiance overflowed single "
                           "precision); no image written");

    std::map<std::string, std::string> attributes = {
        {"mcrt.scene", o.scene},         {"mcrt.estimator", o.estimator},
        {"mcrt.light_select", o.light_select}, {"mcrt.sampler", o.sampler},
        {"mcrt.seed", std::to_string(o.seed)}, {"mcrt.mis_heuristic", o.mis_heuristic}};
    write_exr(o.out, result.image, attributes);
    if (!o.png.empty()) write_png(o.png, result.image, o.exposure);

    double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!o.stats.empty()) {
        uint64_t samples = uint64_t(o.width) * o.height * result.spp;
        nlohmann::json j = {
            {"scene", o.scene},
            {"width", o.width},
            {"height", o.height},
            {"spp", result.spp},
            {"spp_requested", o.spp},
            {"stopped_by", result.stopped_by},
            {"estimator", o.estimator},
            {"light_select", o.light_select},
            {"sampler", o.sampler},
            {"seed", o.seed},
            {"mis_heuristic", o.mis_heuristic},
            {"sky", {settings.sky.r, settings.sky.g, settings.sky.b}},
            {"ao_distance", o.ao_distance},
            {"seconds_total", total},
            {"seconds_render", result.seconds_render},
            {"seconds_kernel_build", result.seconds_build},
            {"seconds_bvh_build", bvh.stats.build_seconds},
            {"samples_per_second", result.seconds_render > 0 ? samples / result.seconds_render : 0.0},
            {"rays", result.rays},
            {"rays_per_second", result.seconds_render > 0 ? result.rays / result.seconds_render : 0.0},
            {"nan_samples", result.nan_samples},
            {"nonfinite_pixels", 0},  // any would have stopped the render above
            {"triangles", scene.triangle_count()},
            {"lights", gpu_scene.lights.size()},
            // The 4-wide tree the kernels traverse; the binary SAH tree it collapses as binary_*.
            {"bvh", {{"nodes", bvh.nodes4.size()}, {"packets", bvh.stats.packets},
                     {"sah_cost", bvh.stats.sah_cost4}, {"depth", bvh.stats.depth4},
                     {"bytes", bvh.stats.bytes}, {"binary_nodes", bvh.nodes.size()},
                     {"binary_sah_cost", bvh.stats.sah_cost}, {"binary_depth", bvh.stats.depth},
                     {"build_seconds", bvh.stats.build_seconds}}},
        };
        // Image-wide means, so that scripts can compare renders without reading EXR.
        std::array<double, 3> mean{}, mean_variance{};
        size_t pixels = size_t(o.width) * o.height;
        for (size_t p = 0; p < pixels; ++p)
            for (int c = 0; c < 3; ++c) {
                mean[c] += result.image.rgb[3 * p + c] / double(pixels);
                mean_variance[c] += result.image.variance[3 * p + c] / double(pixels);
            }
        j["image_mean"] = mean;
        j["image_mean_variance"] = mean_variance;
        nlohmann::json devices_json = nlohmann::json::array();
        for (const DeviceReport& d : result.devices)
            devices_json.push_back({{"name", d.name}, {"index", d.index}, {"samples", d.samples},
                                    {"batches", d.batches}, {"seconds_busy", d.seconds_busy},
                                    {"retired", d.retired},
                                    {"samples_per_second", d.seconds_busy > 0 ? d.samples / d.seconds_busy : 0.0}});
        j["devices"] = devices_json;
        write_atomically(o.stats, [&](const std::string& tmp) {
            std::ofstream out(tmp);
            out << j.dump(2) << "\n";
            if (!out) throw RuntimeError(o.stats + ": cannot write: " + std::strerror(errno ? errno : EIO));
        });
    }
    if (!o.quiet)
        std::cerr << "mcrt: wrote " << o.out << " (" << o.width << "x" << o.height << ", "
                  << result.spp << " spp, " << result.seconds_render << " s on the device)" << std::endl;
    outputs_complete();
    return 0;
}

}  // namespace

int run_cli(int argc, char** argv) {
    CLI::App app{"mcrt — an OpenCL Monte Carlo renderer for light-transport estimator experiments"};
    app.require_subcommand(1);

    app.add_subcommand("devices", "list OpenCL platforms and devices, with their index");

    RenderOptions o;
    CLI::App* render_cmd = app.add_subcommand("render", "render a glTF scene to EXR");
    render_cmd->add_option("scene", o.scene, "glTF scene (.gltf or .glb)")->required();
    render_cmd->add_option("--out", o.out, "output EXR")->required();
    render_cmd->add_option("--png", o.png, "also write an sRGB PNG");
    render_cmd->add_option("--width", o.width, "image width")->capture_default_str()->check(CLI::Range(1, 16384));
    render_cmd->add_option("--height", o.height, "image height")->capture_default_str()->check(CLI::Range(1, 16384));
    render_cmd->add_option("--spp", o.spp, "samples per pixel")->capture_default_str()->check(CLI::Range(1u, 1u << 24));
    render_cmd->add_option("--estimator", o.estimator, "estimator")->capture_default_str()->check(CLI::IsMember(kEstimators));
    render_cmd->add_option("--light-select", o.light_select, "light selection")->capture_default_str()
        ->check(CLI::IsMember({"uniform", "power", "alias"}));
    render_cmd->add_option("--sampler", o.sampler, "sample generator")->capture_default_str()
        ->check(CLI::IsMember({"independent", "stratified", "sobol"}));
    render_cmd->add_option("--mis-heuristic", o.mis_heuristic, "MIS weights (estimator mis)")
        ->capture_default_str()
        ->check(CLI::IsMember({"balance", "power"}));
    render_cmd->add_option("--seed", o.seed, "random seed")->capture_default_str();
    render_cmd->add_option("--sky", o.sky, "sky radiance R,G,B (ambient estimators)")->capture_default_str();
    render_cmd->add_option("--ao-distance", o.ao_distance, "ambient occlusion distance, 0 = unbounded")->capture_default_str()
        ->check(kFinite)->check(CLI::Range(0.0f, 3.4e38f));
    render_cmd->add_option("--camera", o.camera, "camera index in the scene")->check(CLI::Range(0, 1 << 30));
    render_cmd->add_option("--device", o.devices, "device index, cpu, gpu or all (repeatable)");
    render_cmd->add_option("--batch", o.batch, "samples per pixel per launch (0 chooses)")->capture_default_str()
        ->check(CLI::Range(0u, 1u << 24));
    render_cmd->add_option("--stats", o.stats, "write statistics as JSON");
    render_cmd->add_option("--time-limit", o.time_limit, "stop after this many seconds")
        ->check(kFinite)->check(CLI::Range(0.0, 1e9));
    render_cmd->add_option("--exposure", o.exposure, "PNG exposure in stops")->capture_default_str()->check(kFinite)->check(CLI::Range(-64.0f, 64.0f));
    render_cmd->add_flag("--quiet", o.quiet, "no progress output");

    CLI::App* bench_cmd = app.add_subcommand("bench", "time ray queries on a scene");
    BenchOptions bench_options;
    bench_cmd->add_option("scene", bench_options.scene, "glTF scene (.gltf or .glb)")->required();
    bench_cmd->add_option("--rays", bench_options.rays, "ray kind (default: all three)")
        ->check(CLI::IsMember({"primary", "shadow", "ambient"}));
    bench_cmd->add_option("--width", bench_options.width, "image width")->capture_default_str()->check(CLI::Range(1, 16384));
    bench_cmd->add_option("--height", bench_options.height, "image height")->capture_default_str()->check(CLI::Range(1, 16384));
    bench_cmd->add_option("--repeats", bench_options.repeats, "timed runs after a warm-up (median)")
        ->capture_default_str()->check(CLI::Range(1, 1000));
    bench_cmd->add_option("--device", bench_options.device, "device index from `mcrt devices`")
        ->capture_default_str()->check(CLI::Range(0, 1 << 30));
    bench_cmd->add_flag("--json", bench_options.json, "one JSON object per ray kind and line");
    bench_cmd->add_option("--bvh-max-leaf", bench_options.bvh.max_leaf_size, "most triangles in a BVH leaf")
        ->capture_default_str()->check(CLI::Range(1, 64));
    bench_cmd->add_option("--bvh-traversal-cost", bench_options.bvh.traversal_cost,
                          "SAH cost of a node visit, in packet tests")
        ->capture_default_str()->check(kFinite)->check(CLI::Range(0.0f, 100.0f));
    IntegrateOptions integrate_options;
    add_integrate_command(app, integrate_options);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "mcrt: error: " << usage_error_message(app, e, argc, argv) << std::endl;
        return 2;
    }

    try {
        if (app.got_subcommand("devices")) return run_devices();
        if (app.got_subcommand("render")) {
            if (o.width * int64_t(o.height) * o.spp >= (int64_t(1) << 40))
                throw InputError("--width × --height × --spp is too large");
            return run_render(o);
        }
        if (app.got_subcommand("integrate")) return run_integrate(integrate_options);
        if (app.got_subcommand("bench")) return run_bench(bench_options, print_warning);
    } catch (const InputError& e) {
        std::cerr << "mcrt: error: " << e.what() << std::endl;
        return 2;
    } catch (const RuntimeError& e) {
        std::cerr << "mcrt: error: " << e.what() << std::endl;
        return 1;
    } catch (const std::bad_alloc&) {
        std::cerr << "\nmcrt: error: out of host memory" << std::endl;
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "mcrt: error: " << e.what() << std::endl;
        return 1;
    }
    return 2;
}

}  // namespace mcrt
