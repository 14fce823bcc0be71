#include "cli/cli.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "bench/bench.h"
#include "cl/device.h"
#include "cl/no_device.h"
#include "cli/camera_options.h"
#include "cli/integrate.h"
#include "cli/messages.h"
#include "cli/render_command.h"
#include "cli/usage_errors.h"
#include "cli/validators.h"
#include "common/error.h"
#include "mpi/job.h"
#include "render/variants.h"

namespace mcrt {
namespace {

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
        if (!caveats.empty())
            caveats = " (" + caveats + ": the agreement check guards its images)";
        std::printf("%d: %s [%s] — %s (%s), %s, %u compute units, %.1f GiB, driver %s%s\n",
                    d.index, d.name.c_str(), d.type_name().c_str(), d.platform_name.c_str(),
                    d.platform_vendor.c_str(), d.version.c_str(), d.compute_units,
                    double(d.global_memory) / (1 << 30), d.driver_version.c_str(),
                    caveats.c_str());
    }
    return 0;
}

CLI::App* add_bench_command(CLI::App& app, BenchOptions& o, CameraOptions& look) {
    CLI::App* cmd = app.add_subcommand("bench", "time ray queries on a scene");
    cmd->add_option("scene", o.scene, "glTF scene (.gltf or .glb)")->required();
    cmd->add_option("--rays", o.rays, "ray kind (default: all three)")
        ->check(CLI::IsMember({"primary", "shadow", "ambient"}));
    cmd->add_option("--width", o.width, "image width")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
    cmd->add_option("--height", o.height, "image height")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
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
        ->check(kFinite)
        ->check(CLI::Range(0.0f, 100.0f));
    return cmd;
}

}  // namespace

int run_cli(int argc, char** argv) {
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

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // Under mpirun every rank parses the same arguments: rank 0 alone says what is wrong.
        if (job_rank() == 0)
            std::cerr << "mcrt: error: " << usage_error_message(app, e, argc, argv) << std::endl;
        return 2;
    }

    try {
        if (app.got_subcommand("devices")) return run_devices();
        if (app.got_subcommand("variants")) {
            std::cout << (variants_as_json ? variants_json() : variants_text());
            return 0;
        }
        if (app.got_subcommand("render")) return run_render(render_options);
        if (app.got_subcommand("integrate")) return run_integrate(integrate_options);
        if (app.got_subcommand("bench")) {
            bench_options.camera = look_at_camera(bench_look);
            return run_bench(bench_options, print_warning);
        }
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
