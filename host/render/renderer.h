// Rendering a scene on a device: batching, the render and reduction kernels, accumulation.
#pragma once

#include <csignal>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "cl/device.h"
#include "common/stop_signals.h"
#include "image/image.h"
#include "render/gpu_scene.h"

namespace mcrt {

// What a render is, as plain data: variants are named as in the tables of render/variants.h and
// resolved once into a plan (render/plan.h).
struct RenderSettings {
    int width = 512, height = 512;
    uint32_t spp = 16;
    std::string estimator = "light-area";   // a row of kEstimatorVariants; unused with a file
    std::string estimator_file;             // a user's estimator (--estimator-file), "" for none
    std::string estimator_source;           // its text (read_estimator_file)
    std::string light_select = "power";     // kLightSelectVariants
    std::string sampler = "independent";    // kSamplerVariants
    std::string mis_heuristic = "balance";  // kMisHeuristicVariants
    std::string materials = "gltf";         // kMaterialVariants (the scene is read accordingly)
    glm::vec3 sky{1.0f};       // ambient estimators: uniform sky radiance; else the sky light's
    bool sky_light = false;    // direct and path estimators: the sky is a light (--sky given)
    float ao_distance = 0.0f;  // ambient estimators: occlusion range, 0 = unbounded
    // An environment map (--env: .exr or .hdr, "" for none) in place of the uniform sky: the
    // ambient estimators' sky, and for the others a light beside the area lights.
    std::string env;
    float env_scale = 1.0f;   // multiplies its texels
    float env_rotate = 0.0f;  // degrees about +Y, counter-clockwise seen from above
    uint32_t max_depth = 1;   // reflections per path, 0 .. MCRT_MAX_PATH_DEPTH; 1: direct light
    uint32_t rr_depth = 5;    // Russian roulette before reflection k + 1 for every k >= rr_depth
    uint32_t seed = 0;
    uint32_t batch = 0;  // samples per pixel per launch; 0 chooses; rounded up to whole chunks
    // Independent randomizations of the sampler the variance layer is estimated from (1: the
    // samples' own variance); divides 16 and spp. resolve_replicates() chooses it from 0.
    uint32_t replicates = 1;
};

struct DeviceReport {
    std::string name;
    int index = 0;  // as `mcrt devices` lists it
    uint64_t samples = 0;
    uint64_t batches = 0;
    double seconds_busy = 0;  // kernel time from profiling events
    bool retired = false;     // failed during the render; its work was redone elsewhere
    int rank = 0;             // the MPI rank it belongs to (0 without MPI)
};

class RenderWorker;  // render/render_worker.h
// Called once the local devices are set up: devices of other MPI ranks that render beside them
// (host/mpi/), or none.
using RemoteWorkers = std::function<std::vector<std::unique_ptr<RenderWorker>>()>;

struct RenderResult {
    Image image;
    uint32_t replicates = 1;         // what the variance layer was estimated from (1: the samples)
    uint64_t variance_clamped = 0;   // variance values beyond float's range, written as FLT_MAX
    uint32_t spp = 0;                // samples per pixel in the image (fewer if stopped early)
    std::string stopped_by;          // "", "time limit" or "interrupt"
    uint64_t nan_samples = 0;        // non-finite samples, left out of the image
    uint64_t rays = 0;               // camera and shadow rays traced
    uint64_t path_vertices = 0;      // surface points the paths reached (the camera's hit included)
    uint64_t roulette_ends = 0;      // paths that Russian roulette ended
    double seconds_render = 0;       // kernel time summed over devices (profiling events)
    double seconds_build = 0;        // kernel compilation and scene upload
    double seconds_render_wall = 0;  // wall clock from the first launch to the last result
    double seconds_first_batch = 0;  // wall clock from render() to the first batch accumulated
    // With RenderControl::keep_replicate_means and more than one replicate: each replicate's
    // mean image, as Accumulator::replicate_means() orders it; else empty.
    std::vector<float> replicate_means;
    std::vector<DeviceReport> devices;
};

// Progress: samples per pixel in the image so far, of the total, and each device's share.
using ProgressSink =
    std::function<void(uint32_t done, uint32_t total, const std::vector<DeviceReport>& devices)>;

// How a render may end early: a time limit (0 = none) and a flag set from a signal handler;
// and what it keeps beside the image.
struct RenderControl {
    double time_limit = 0;
    const StopFlag* interrupted = nullptr;  // common/stop_signals.h
    // Called once when the kernels are about to run: after the builds and, in an MPI job, the
    // other ranks' setup (the supervisor's time limit counts from here, host/cli/supervisor.h).
    std::function<void()> launching;
    // Keep each replicate's mean image (RenderResult::replicate_means): the Python module's
    // Result.replicate_images; the command line writes none.
    bool keep_replicate_means = false;
};

struct RenderPlan;  // render/plan.h

// One local device's worker for a render: a DeviceWorker that uploads the scene itself, or one
// on a session's upload (render/session.h). Throws RuntimeError when the device cannot render.
using WorkerFactory = std::function<std::unique_ptr<RenderWorker>(const DeviceContext&)>;

// Renders the plan on the workers `make_worker` sets up on the devices, as render() below does
// (render() is this with workers that upload the scene themselves).
RenderResult render_with_workers(const std::vector<const DeviceContext*>& devices,
                                 const WorkerFactory& make_worker, const RenderPlan& plan,
                                 const ProgressSink& progress = {},
                                 const RenderControl& control = {},
                                 const std::function<void(const std::string&)>& warn = {},
                                 const RemoteWorkers& remote = {});

// Renders the plan on every device at once: work is handed out dynamically, each device's
// launches sized to take about 150 ms; a device that fails is retired with a warning and its
// work redone on the others. The image is bitwise identical whatever the devices, batch sizes
// and timing (for devices that round identically). Throws RuntimeError when no device can
// render. `remote` adds the devices of other MPI ranks, handed work from the same queue.
RenderResult render(const std::vector<const DeviceContext*>& devices, const GpuSceneData& scene,
                    const RenderPlan& plan, const ProgressSink& progress = {},
                    const RenderControl& control = {},
                    const std::function<void(const std::string&)>& warn = {},
                    const RemoteWorkers& remote = {});

// The same for settings not yet planned (make_render_plan; throws SettingError for settings it
// cannot honour).
RenderResult render(const std::vector<const DeviceContext*>& devices, const GpuSceneData& scene,
                    const RenderSettings& settings, const ProgressSink& progress = {},
                    const RenderControl& control = {},
                    const std::function<void(const std::string&)>& warn = {},
                    const RemoteWorkers& remote = {});

// One device, no early stop.
RenderResult render(const DeviceContext& device, const GpuSceneData& scene,
                    const RenderSettings& settings);

// Replicates for `requested` (0: the default of the settings' variants, RenderVariants::
// correlated) with the settings' spp: a power of two dividing 16 and spp. Throws SettingError
// for a requested count that is not one (render/plan.cpp).
uint32_t resolve_replicates(uint32_t requested, const RenderSettings& settings);

// Samples per pixel per launch when --batch is given: rounded up to whole chunks, at most spp
// rounded up.
uint32_t batch_samples_per_pixel(uint32_t requested, int width, int height, uint32_t spp);

}  // namespace mcrt
