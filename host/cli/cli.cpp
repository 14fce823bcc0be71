#include "cli/cli.h"

#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <system_error>

#include "bench/bench.h"
#include "cl/device.h"
#include "cl/no_device.h"
#include "cli/camera_options.h"
#include "cli/integrate.h"
#include "cli/messages.h"
#include "cli/render_command.h"
#include "cli/usage_errors.h"
#include "cli/validators.h"
#include "common/activity.h"
#include "common/error.h"
#include "mpi/job.h"
#include "render/variants.h"

namespace mcrt {
namespace {

// Whether descriptor 1 was closed (`mcrt devices >&-`); if so /dev/null holds it, so that no file
// opened later (a cache, a library) becomes stdout and receives what is printed.
bool hold_closed_stdout() {
    if (::fcntl(STDOUT_FILENO, F_GETFD) != -1 || errno != EBADF) return false;
    const int fd = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (fd >= 0 && fd != STDOUT_FILENO) {
        ::dup2(fd, STDOUT_FILENO);
        ::close(fd);
    }
    return true;
}

// `status`, once everything printed has reached stdout; a write that failed there (ENOSPC on
// /dev/full, EPIPE, EIO: write(2)) is a runtime failure, as a lost result must not exit 0. The
// reason is errno of the write that failed (stdio keeps only the error flag): clear errno before
// printing.
int finish_stdout(int status) {
    std::cout.flush();
    const bool ok = std::cout.good() && std::fflush(stdout) == 0 && !std::ferror(stdout);
    if (!ok)
        throw RuntimeError(std::string("cannot write to stdout: ") +
                           std::strerror(errno ? errno : EIO));
    return status;
}

// "out of host memory while building the BVH": what ran out and what mcrt was doing.
std::string resource_message(const std::string& what) {
    const std::string activity = current_activity();
    return activity.empty() ? what : what + " while " + activity;
}

int run_devices() {
    std::vector<DeviceInfo> devices = enumerate_devices(print_warning);
    if (devices.empty()) throw RuntimeError(no_device_message());
    for (const DeviceInfo& d : devices) {
        // What the device does not promise of IEEE-754 arithmetic (docs/DESIGN.md, "Data flow").
        std::string caveats;
        if (!(d.single_fp_config & CL_FP_DENORM)) caveats += "may flush denormals";
        if (!(d.single_fp_config & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT))
            caveats += std::string(caveats.empty() ? "" : ", ") +
                       "does not promise correctly rounded division and sqrt";
        if (!caveats.empty()) caveats = " (" + caveats + ": the agreement check guards its images)";
        std::printf("%d: %s [%s] — %s (%s), %s, %u compute units, %.1f GiB, driver %s%s\n", d.index,
                    d.name.c_str(), d.type_name().c_str(), d.platform_name.c_str(),
                    d.platform_vendor.c_str(), d.version.c_str(), d.compute_units,
                    double(d.global_memory) / (1 << 30), d.driver_version.c_str(), caveats.c_str());
    }
    return 0;
}

CLI::App* add_bench_command(CLI::App& app, BenchOptions& o, CameraOptions& look) {
    CLI::App* cmd = app.add_subcommand("bench", "time ray queries on a scene");
    cmd->add_option("scene", o.scene, "glTF scene (.gltf or .glb)")->required();
    cmd->add_option("--rays", o.rays, "ray kind (default: all three)")
        ->check(CLI::IsMember({"primary", "shadow", "ambient"}));
    add_image_size_options(cmd, o.width, o.height);
    cmd->add_option("--repeats", o.repeats, "timed runs after a warm-up (median)")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--device", o.device, "device index from `mcrt devices`")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 30));
    cmd->add_flag("--json", o.json, "one JSON object per ray kind and line");
    add_camera_options(cmd, look);
    cmd->add_option("--bvh-max-leaf", o.bvh.max_leaf_size, "most triangles in a BVH leaf")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("--bvh-traversal-cost", o.bvh.traversal_cost,
                    "SAH cost of a node visit, in packet tests")
        ->capture_default_str()
        ->check(kFiniteFloat)
        ->check(CLI::Range(0.0f, 100.0f));
    return cmd;
}

}  // namespace

int run_cli(int argc, char** argv) {
    const bool stdout_closed = hold_closed_stdout();
    CLI::App app{"mcrt — an OpenCL Monte Carlo renderer for light-transport estimator experiments"};
    app.require_subcommand(1);

    app.add_subcommand("devices", "list OpenCL platforms and devices, with their index");
    bool variants_as_json = false;
    app.add_subcommand("variants",
                       "list every estimator, light selection, sampler and MIS heuristic")
        ->add_flag("--json", variants_as_json, "as JSON (what the scripts read)");
    RenderOptions render_options;
    add_render_command(app, render_options);
    BenchOptions bench_options;
    CameraOptions bench_look;
    add_bench_command(app, bench_options, bench_look);
    IntegrateOptions integrate_options;
    add_integrate_command(app, integrate_options);
    refuse_empty_values(app);  // every string-valued option of every subcommand

    std::string refused;      // a usage error
    std::exception_ptr help;  // --help, printed once the ranks agree
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        help = std::current_exception();
    } catch (const CLI::CallForAllHelp&) {
        help = std::current_exception();
    } catch (const CLI::ParseError& e) {
        refused = usage_error_message(app, e, argc, argv);
    }
    // Under mpirun every rank reads its own command line: rank 0's is the request, and a rank
    // that reads another (other options, a usage error of its own) ends the job at once.
    if (job_size() > 1) {
        std::vector<std::string> command = {std::string("mcrt ") + (argc > 1 ? argv[1] : "") +
                                            (help ? " --help" : "")};
        if (refused.empty() && !help && app.got_subcommand("render")) {
            const std::vector<std::string> words = render_option_words(render_options);
            command.insert(command.end(), words.begin(), words.end());
        }
        if (const int status = agree_on_command(command, refused); status != 0) {
            if (job_rank() == 0 && !refused.empty())
                std::cerr << "mcrt: error: " << refused << std::endl;
            return status;
        }
    }
    if (help) {
        try {
            std::rethrow_exception(help);
        } catch (const CLI::ParseError& e) {
            return app.exit(e);
        }
    }
    if (!refused.empty()) {
        std::cerr << "mcrt: error: " << refused << std::endl;
        return 2;
    }

    try {
        // What prints its result on stdout fails when it cannot (integrate checks its own).
        const bool prints = app.got_subcommand("devices") || app.got_subcommand("variants") ||
                            app.got_subcommand("bench");
        if (prints && stdout_closed) throw RuntimeError("cannot write to stdout: it is closed");
        errno = 0;
        if (app.got_subcommand("devices")) return finish_stdout(run_devices());
        if (app.got_subcommand("variants")) {
            errno = 0;
            std::cout << (variants_as_json ? variants_json() : variants_text());
            return finish_stdout(0);
        }
        if (app.got_subcommand("render")) return run_render(render_options);
        if (app.got_subcommand("integrate")) return run_integrate(integrate_options);
        if (app.got_subcommand("bench")) {
            bench_options.camera = look_at_camera(bench_look);
            return finish_stdout(run_bench(bench_options, print_warning));
        }
    } catch (const InputError& e) {
        std::cerr << "mcrt: error: " << e.what() << std::endl;
        return 2;
    } catch (const RuntimeError& e) {
        std::cerr << "mcrt: error: " << e.what() << std::endl;
        return 1;
    } catch (const std::bad_alloc&) {
        std::cerr << "mcrt: error: " << resource_message("out of host memory") << std::endl;
        return 1;
    } catch (const std::system_error& e) {
        // std::thread's EAGAIN: no thread to be had (RLIMIT_NPROC, or memory for its stack).
        std::cerr << "mcrt: error: "
                  << (e.code() == std::errc::resource_unavailable_try_again
                          ? resource_message("cannot start a thread (" + e.code().message() +
                                             ": a process or memory limit)")
                          : std::string(e.what()))
                  << std::endl;
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "mcrt: error: " << e.what() << std::endl;
        return 1;
    }
    return 2;
}

}  // namespace mcrt
