// `mcrt render`: its options, their validation, and the render that writes EXR, PNG and stats.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cli/camera_options.h"
#include "common/error.h"
#include "render/plan.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace mcrt {

struct RenderOptions {
    std::string scene, out, png, stats;
    int width = 512, height = 512;
    uint32_t spp = 16;
    std::string estimator = "light-area", estimator_file;
    std::string light_select = "power", sampler = "independent", mis_heuristic = "balance";
    std::string materials = "gltf";
    uint32_t seed = 0;
    std::string sky;  // "": not given (the ambient estimators' sky is 1, the others have none)
    float ao_distance = 0.0f;
    std::string env;  // "": none (RenderSettings::env)
    float env_scale = 1.0f, env_rotate = 0.0f;
    uint32_t max_depth = 1, rr_depth = 5;
    int camera = -1;
    CameraOptions look;  // --look-from ...: replaces the scene's camera
    std::vector<std::string> devices;
    uint32_t batch = 0;
    uint32_t replicates = 0;  // 0: the default (resolve_replicates)
    double time_limit = 0.0;
    float exposure = 0.0f;
    bool quiet = false;
};

// Every option of `render` but --device (which names each machine's own devices), as this
// process read it: "the scene S", "--width 64", "no --png", "--quiet"; one entry per option,
// always in the same order. Under MPI every rank's must equal rank 0's (agree_on_command,
// host/mpi/job.h).
std::vector<std::string> render_option_words(const RenderOptions& o);

// Adds the `render` subcommand, its options filling `o`.
CLI::App* add_render_command(CLI::App& app, RenderOptions& o);

// Runs it; returns the exit status, throws InputError / RuntimeError (run_cli prints them).
// Under mpirun or srun, rank 0 runs the command and the other ranks render with it
// (host/mpi/job.h).
int run_render(const RenderOptions& o);

// The request the options make (render/plan.h), as every rank of an MPI render reads it alike;
// the estimator file's text is read on rank 0 alone (the others get it from rank 0).
RenderRequest render_request(const RenderOptions& o);

// A setting the render library refused (SettingError), said with the command line's flag.
InputError flag_error(const SettingError& e);

// What a finished render must pass before it is written: its non-finite samples are told to
// `warn` (counted as 0 by the kernels); throws RuntimeError when every sample, or any pixel, is
// not finite.
void check_render_result(const RenderResult& result, const WarningSink& warn);

// The EXR header attributes of a render of these options (DESIGN.md "Outputs").
std::map<std::string, std::string> exr_attributes(const RenderOptions& o,
                                                  const RenderResult& result);

}  // namespace mcrt
