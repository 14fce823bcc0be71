#include "cli/render_command.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>

#include "bvh/bvh.h"
#include "cl/build_child.h"
#include "cl/device_select.h"
#include "cli/messages.h"
#include "cli/progress.h"
#include "cli/stats_json.h"
#include "cli/supervisor.h"
#include "cli/validators.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/output_paths.h"
#include "common/stop_signals.h"
#include "common/test_hooks.h"
#include "common/value_limits.h"
#include "image/image.h"
#include "image/image_check.h"
#include "mpi/job.h"
#include "render/estimator_file.h"
#include "render/memory_estimate.h"
#include "render/render_program.h"
#include "render/renderer.h"
#include "render/session.h"
#include "render/variants.h"
#include "scene/gltf_import.h"

namespace mcrt {
namespace {

StopFlag g_interrupted{0};

extern "C" void on_interrupt(int) { g_interrupted = 1; }

// While a render runs, SIGINT, SIGTERM and SIGHUP (kStopSignals) ask it to stop and write the
// samples done so far; a second signal ends the process at once. SIGHUP stays ignored where the
// process started with it ignored (nohup).
struct InterruptGuard {
    InterruptGuard() {
        g_interrupted = 0;
        set_build_stop_flag(&g_interrupted);  // a kernel build in a child process stops too
        set_stop_flag(&g_interrupted);        // so does the output commit's wait for a lock
        struct sigaction action {};
        action.sa_handler = on_interrupt;
        action.sa_flags = SA_RESETHAND;
        sigemptyset(&action.sa_mask);
        for (size_t i = 0; i < std::size(kStopSignals); ++i) {
            sigaction(kStopSignals[i], nullptr, &old[i]);
            if (ignored_at_start(kStopSignals[i])) continue;
            sigaction(kStopSignals[i], &action, nullptr);
        }
    }
    ~InterruptGuard() {
        if (outputs_are_complete()) return;  // stop signals stay ignored: nothing left to save
        for (size_t i = 0; i < std::size(kStopSignals); ++i)
            sigaction(kStopSignals[i], &old[i], nullptr);
    }
    struct sigaction old[std::size(kStopSignals)]{};
};

glm::vec3 parse_sky(const std::string& text) {
    std::vector<float> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        // Checked as a double: std::stof refused a radiance below float's smallest (1e-50) as
        // out of range though it is in [0, 1e30]; as a float it is 0 or a denormal.
        char* end = nullptr;
        const double x = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(x) || x < 0 ||
            x > kMaxRadiance)
            throw InputError("--sky " + text + ": expected R,G,B or one value, each in [0, 1e30]");
        v.push_back(std::strtof(item.c_str(), nullptr));  // rounded once, as std::stof did
    }
    if (!text.empty() && text.back() == ',')  // getline drops the empty last value
        throw InputError("--sky " + text + ": expected R,G,B or one value");
    if (v.size() == 1) return glm::vec3(v[0]);
    if (v.size() == 3) return glm::vec3(v[0], v[1], v[2]);
    throw InputError("--sky " + text + ": expected R,G,B or one value");
}

// One line per row: "name  description", for --help.
template <typename Table>
std::string help_list(const char* what, const Table& table) {
    std::string text = what;
    for (const auto& row : table) text += std::string("\n  ") + row.name + ": " + row.description;
    return text;
}

// Non-finite samples are counted as 0 (kernels/render/render.cl, reduce_chunks): say so, and refuse
// an image that holds nothing else.
void report_nonfinite_samples(uint64_t nonfinite, uint64_t samples, const WarningSink& warn) {
    if (nonfinite == 0 || samples == 0) return;
    const std::string count = std::to_string(nonfinite) + " of " + std::to_string(samples);
    if (nonfinite >= samples)
        throw RuntimeError("all " + std::to_string(samples) +
                           " samples were not finite (NaN or infinite); no image written");
    const double percent = 100.0 * double(nonfinite) / double(samples);
    char share[32];
    if (percent < 0.05)
        std::snprintf(share, sizeof share, "under 0.1%%");
    else if (percent > 99.95)
        std::snprintf(share, sizeof share, "over 99.9%%");
    else
        std::snprintf(share, sizeof share, "%.1f%%", percent);
    if (warn)
        warn(count + " samples (" + share +
             ") were not finite (NaN or infinite) and were counted as 0");
}

}  // namespace

void check_render_result(const RenderResult& result, const WarningSink& warn) {
    const uint64_t samples =
        uint64_t(result.image.width) * uint64_t(result.image.height) * result.spp;
    report_nonfinite_samples(result.nan_samples, samples, warn);
    if (uint64_t bad = nonfinite_pixels(result.image))
        throw RuntimeError(std::to_string(bad) +
                           " pixels are not finite (radiance overflowed single "
                           "precision); no image written");
}

std::map<std::string, std::string> exr_attributes(const RenderOptions& o,
                                                  const RenderResult& result) {
    std::map<std::string, std::string> attributes = {
        {"mcrt.scene", o.scene},
        {"mcrt.estimator", o.estimator_file.empty() ? o.estimator : o.estimator_file},
        {"mcrt.light_select", o.light_select},
        {"mcrt.sampler", o.sampler},
        {"mcrt.seed", std::to_string(o.seed)},
        {"mcrt.mis_heuristic", o.mis_heuristic},
        {"mcrt.materials", o.materials},
        {"mcrt.replicates", std::to_string(result.replicates)},
        {"mcrt.variance",
         result.replicates > 1
             ? "variance of the pixel mean from the spread of " +
                   std::to_string(result.replicates) + " independent replicate means"
             : "variance of the pixel mean: the samples' variance over their number"}};
    // Only with a map: a render without one keeps its file's bytes.
    if (!o.env.empty()) attributes["mcrt.env"] = o.env;
    return attributes;
}

RenderRequest render_request(const RenderOptions& o) {
    RenderRequest r;
    r.scene = o.scene;
    RenderSettings& settings = r.settings;
    settings.width = o.width;
    settings.height = o.height;
    settings.spp = o.spp;
    settings.estimator = o.estimator;
    if (!o.estimator_file.empty()) {
        settings.estimator_file = o.estimator_file;
        // Rank 0 reads the file; the other ranks get its text from rank 0 (serve_render).
        if (job_rank() == 0) settings.estimator_source = read_estimator_file(o.estimator_file);
    }
    settings.light_select = o.light_select;
    settings.sampler = o.sampler;
    settings.mis_heuristic = o.mis_heuristic;
    settings.materials = o.materials;
    if (!o.sky.empty()) r.sky = parse_sky(o.sky);
    settings.ao_distance = o.ao_distance;
    settings.env = o.env;
    settings.env_scale = o.env_scale;
    settings.env_rotate = o.env_rotate;
    settings.max_depth = o.max_depth;
    settings.rr_depth = o.rr_depth;
    settings.seed = o.seed;
    settings.batch = o.batch;
    settings.replicates = o.replicates;
    r.camera.index = o.camera;
    r.camera.look = look_at_camera(o.look);  // a bad --look-from ... is refused here
    return r;
}

InputError flag_error(const SettingError& e) {
    std::string flag = "--" + e.setting;
    for (char& c : flag)
        if (c == '_') c = '-';
    return InputError(flag + " " + e.detail);
}

std::vector<std::string> render_option_words(const RenderOptions& o) {
    auto text = [](const char* name, const std::string& value) {
        return value.empty() ? std::string("no ") + name : std::string(name) + " " + value;
    };
    auto number = [](const char* format, double v) {
        char digits[40];
        std::snprintf(digits, sizeof digits, format, v);
        return std::string(digits);
    };
    auto flag = [](const char* name, bool on) { return (on ? "" : std::string("no ")) + name; };
    return {"the scene " + o.scene,
            text("--out", o.out),
            text("--png", o.png),
            text("--stats", o.stats),
            "--width " + std::to_string(o.width),
            "--height " + std::to_string(o.height),
            "--spp " + std::to_string(o.spp),
            "--estimator " + o.estimator,
            text("--estimator-file", o.estimator_file),
            "--light-select " + o.light_select,
            "--sampler " + o.sampler,
            "--mis-heuristic " + o.mis_heuristic,
            "--materials " + o.materials,
            "--seed " + std::to_string(o.seed),
            text("--sky", o.sky),
            text("--env", o.env),
            "--env-scale " + number("%.9g", o.env_scale),
            "--env-rotate " + number("%.9g", o.env_rotate),
            "--max-depth " + std::to_string(o.max_depth),
            "--rr-depth " + std::to_string(o.rr_depth),
            "--ao-distance " + number("%.9g", o.ao_distance),
            o.camera < 0 ? "no --camera" : "--camera " + std::to_string(o.camera),
            text("--look-from", o.look.look_from),
            text("--look-at", o.look.look_at),
            "--up " + o.look.up,
            "--fov " + number("%.9g", o.look.fov),
            "--batch " + std::to_string(o.batch),
            "--replicates " + std::to_string(o.replicates),
            o.time_limit > 0 ? "--time-limit " + number("%.17g", o.time_limit) : "no --time-limit",
            "--exposure " + number("%.9g", o.exposure),
            flag("--quiet", o.quiet)};
}

CLI::App* add_render_command(CLI::App& app, RenderOptions& o) {
    CLI::App* cmd = app.add_subcommand("render", "render a glTF scene to EXR");
    cmd->add_option("scene", o.scene, "glTF scene (.gltf or .glb)")->required();
    cmd->add_option("--out", o.out, "output EXR")->required();
    cmd->add_option("--png", o.png, "also write an sRGB PNG");
    add_image_size_options(cmd, o.width, o.height);
    cmd->add_option("--spp", o.spp, "samples per pixel")
        ->capture_default_str()
        ->check(CLI::Range(1u, 1u << 24));
    CLI::Option* estimator =
        cmd->add_option("--estimator", o.estimator, help_list("estimator:", kEstimatorVariants))
            ->capture_default_str()
            ->check(CLI::IsMember(variant_names(kEstimatorVariants)));
    cmd->add_option(
           "--estimator-file", o.estimator_file,
           "a user's estimator: an OpenCL C file defining float3 estimate(...) against the "
           "kernel API of docs/ESTIMATORS.md")
        ->excludes(estimator);
    cmd->add_option("--light-select", o.light_select,
                    help_list("light selection:", kLightSelectVariants))
        ->capture_default_str()
        ->check(CLI::IsMember(variant_names(kLightSelectVariants)));
    cmd->add_option("--sampler", o.sampler, help_list("sample generator:", kSamplerVariants))
        ->capture_default_str()
        ->check(CLI::IsMember(variant_names(kSamplerVariants)));
    cmd->add_option("--mis-heuristic", o.mis_heuristic,
                    help_list("MIS weights (estimators that use them):", kMisHeuristicVariants))
        ->capture_default_str()
        ->check(CLI::IsMember(variant_names(kMisHeuristicVariants)));
    cmd->add_option("--materials", o.materials, help_list("surfaces:", kMaterialVariants))
        ->capture_default_str()
        ->check(CLI::IsMember(variant_names(kMaterialVariants)));
    cmd->add_option("--seed", o.seed, "random seed")->capture_default_str();
    CLI::Option* sky =
        cmd->add_option("--sky", o.sky,
                        "uniform sky radiance R,G,B: the ambient estimators' sky (default 1), or a "
                        "light at infinity for the others (default: none, black)");
    cmd->add_option("--env", o.env,
                    "environment map (.exr or .hdr, latitude-longitude, Mitsuba's envmap for +Y "
                    "up) in place of --sky: the ambient estimators' sky, or a light at infinity "
                    "for the others, sampled by its texels")
        ->excludes(sky);
    cmd->add_option("--env-scale", o.env_scale, "multiplies the environment map's texels")
        ->capture_default_str()
        ->check(kFiniteFloat)
        ->check(CLI::Range(0.0f, 1e30f));
    cmd->add_option("--env-rotate", o.env_rotate,
                    "turns the environment map about +Y by this many degrees (counter-clockwise "
                    "seen from above)")
        ->capture_default_str()
        ->check(kFiniteFloat)
        ->check(CLI::Range(-36000.0f, 36000.0f));
    cmd->add_option("--max-depth", o.max_depth,
                    "reflections per path: 1 direct lighting, 0 emitted light only, up to " +
                        std::to_string(MCRT_MAX_PATH_DEPTH) + " path tracing")
        ->capture_default_str()
        ->check(CLI::Range(0u, MCRT_MAX_PATH_DEPTH));
    cmd->add_option("--rr-depth", o.rr_depth,
                    "Russian roulette decides whether a path goes on past its k-th reflection for "
                    "every k >= this")
        ->capture_default_str()
        ->check(CLI::Range(1u, MCRT_MAX_PATH_DEPTH));
    cmd->add_option("--ao-distance", o.ao_distance, "ambient occlusion distance, 0 = unbounded")
        ->capture_default_str()
        ->check(kFiniteFloat)
        ->check(CLI::Range(0.0f, 3.4e38f));
    CLI::Option* camera =
        cmd->add_option("--camera", o.camera, "glTF camera index in the scene (cameras[K])")
            ->check(CLI::Range(0, 1 << 30));
    add_camera_options(cmd, o.look, camera);
    cmd->add_option("--device", o.devices,
                    "device index, cpu, gpu, all or a platform such as pocl or intel (repeatable)");
    cmd->add_option("--batch", o.batch, "samples per pixel per launch (0 chooses)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 1u << 24));
    cmd->add_option("--replicates", o.replicates,
                    "independent randomizations of the sampler that the variance layer is "
                    "estimated from (1, 2, 4, 8, 16 dividing --spp; 0: 1 for independent samples, "
                    "else " +
                        std::to_string(kDefaultReplicates) +
                        " or the largest power of two dividing --spp)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 16u));
    cmd->add_option("--stats", o.stats, "write statistics as JSON");
    cmd->add_option("--time-limit", o.time_limit, "stop after this many seconds")
        ->check(kFinite)
        ->check(CLI::Range(0.0, 1e9));
    cmd->add_option("--exposure", o.exposure, "PNG exposure in stops")
        ->capture_default_str()
        ->check(kFiniteFloat)
        ->check(CLI::Range(-64.0f, 64.0f));
    cmd->add_flag("--quiet", o.quiet, "no progress output");
    return cmd;
}

namespace {

// The command on rank 0 (or alone): with a job, the other ranks get the inputs and render too.
int render_here(const RenderOptions& o, RenderJob* job) {
    auto start = std::chrono::steady_clock::now();
    if (o.width * int64_t(o.height) * o.spp >= (int64_t(1) << 40))
        throw InputError("--width × --height × --spp is too large");
    // Every output is checked and its temporary created before anything is loaded; they land
    // together at the end, or none does (OutputSet).
    OutputSet outputs;
    outputs.add("--out", o.out);
    outputs.add("--png", o.png);
    outputs.add("--stats", o.stats);
    std::vector<std::string> inputs = {o.scene};
    if (!o.estimator_file.empty()) inputs.push_back(o.estimator_file);
    if (!o.env.empty()) inputs.push_back(o.env);
    outputs.prepare(inputs);
    if (!o.estimator_file.empty()) report_to_supervisor("estimator " + o.estimator_file);
    const RenderRequest request = render_request(o);

    FileBundle files;  // what the other ranks load the scene from
    SceneSource source;
    source.files_read = &inputs;
    source.record = job ? &files : nullptr;
    // Settings are refused before the scene is read.
    const RenderPlan checked = check_render_settings(request.settings, request.sky);
    const std::shared_ptr<SessionScene> scene =
        load_session_scene(request.scene, checked.settings.materials,
                           checked.variants.light_select->id, source, print_warning);
    const RenderPlan plan = plan_session_render(*scene, request, print_warning, source);
    const RenderSettings& settings = plan.settings;
    outputs.check_inputs(inputs);  // its buffers too
    check_host_memory("a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " render",
                      render_host_bytes(o.width, o.height, settings.replicates));
    if (job) {
        job->share_inputs(files, settings.estimator_source);
        files.clear();
    }

    RenderSession session(select_devices(o.devices, print_warning), print_warning);

    RenderControl control;
    control.time_limit = o.time_limit;
    control.interrupted = &g_interrupted;
    control.launching = [&] {
        // Every digit: std::to_string's six decimals would make a limit below 5e-7 s "0", none.
        char limit[32];
        std::snprintf(limit, sizeof limit, "%.17g", o.time_limit);
        report_to_supervisor(std::string("launch ") + limit + (o.quiet ? " 0" : " 1"));
    };
    InterruptGuard interrupt_guard;  // SIGINT / SIGTERM / SIGHUP: stop and write what is done
    ProgressBar bar(!o.quiet, uint64_t(o.width) * o.height);
    const double seconds_to_render =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    RenderResult result = session.render(
        scene, plan,
        [&](uint32_t done, uint32_t total, const std::vector<DeviceReport>& d) {
            bar.update(done, total, d);
        },
        control, print_warning, job ? job->remote_workers(print_warning) : RemoteWorkers{});
    bar.finish();
    report_to_supervisor("writing");
    if (!result.stopped_by.empty())
        print_warning("stopped by " + result.stopped_by + " after " + std::to_string(result.spp) +
                      " of " + std::to_string(o.spp) + " samples per pixel; writing those");
    check_render_result(result, print_warning);

    const std::map<std::string, std::string> attributes = exr_attributes(o, result);
    test_pause("before-write");
    write_exr_to(outputs.temporary(o.out), o.out, result.image, attributes);
    if (!o.png.empty()) write_png_to(outputs.temporary(o.png), o.png, result.image, o.exposure);

    double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!o.stats.empty()) {
        nlohmann::json j =
            render_stats_json({o, plan, scene->prepared, result, total, seconds_to_render});
        if (job) j["ranks"] = job->ranks_json(result.devices);
        errno = 0;
        std::ofstream out(outputs.temporary(o.stats), std::ios::trunc);
        out << j.dump(2) << "\n";
        out.close();
        if (!out)
            throw RuntimeError(o.stats + ": cannot write: " + std::strerror(errno ? errno : EIO));
    }
    outputs.commit();
    if (!o.quiet)
        std::cerr << "mcrt: wrote " << o.out << " (" << o.width << "x" << o.height << ", "
                  << result.spp << " spp, " << result.seconds_render << " s on the device)"
                  << std::endl;
    outputs_complete();
    report_to_supervisor("done");
    return 0;
}

int render_in_job(const RenderOptions& o) {
    if (job_size() == 1) return render_here(o, nullptr);
    report_to_supervisor("rank " + std::to_string(job_rank()));
    if (job_rank() > 0) {
        if (!o.estimator_file.empty()) report_to_supervisor("estimator " + o.estimator_file);
        report_to_supervisor("serve");  // rank 0 decides when this rank stops
        return serve_render([&] { return render_request(o); }, o.devices);
    }
    // Every rank exits with rank 0's status; its error line is printed by run_cli alone.
    RenderJob job;
    try {
        const int status = render_here(o, &job);
        job.finish(status);
        return status;
    } catch (const SettingError& e) {
        job.finish(2, flag_error(e).what());
        throw;
    } catch (const InputError& e) {
        job.finish(2, e.what());
        throw;
    } catch (const std::exception& e) {
        job.finish(1, e.what());
        throw;
    } catch (...) {
        job.finish(1);
        throw;
    }
}

}  // namespace

int run_render(const RenderOptions& o) {
    try {
        return render_in_job(o);
    } catch (const SettingError& e) {
        throw flag_error(e);  // the settings' words, as the command line's flags
    }
}

}  // namespace mcrt
