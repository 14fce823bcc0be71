// One plan per render: a request of plain data (filled by the command line on every rank of a
// job) goes into plan_render, which validates it once, resolves its variants to typed rows once,
// and builds the scene, its camera, BVH and device scene, the kernel options and the batch size,
// each once. The command line, every MPI rank (host/mpi) and `mcrt bench` (the scene part)
// consume plans; render() (renderer.h) runs one.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "render/environment_light.h"
#include "render/gpu_scene.h"
#include "render/renderer.h"
#include "render/variants.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"

namespace mcrt {

// Which camera sees the scene: the look-at camera if given, else the scene's camera `index`
// (-1: its first, or bench_camera when it has none).
struct CameraChoice {
    int index = -1;
    std::optional<Camera> look;
};

// What a render is asked to be, as plain data. settings.sky and settings.sky_light are the
// plan's to resolve from `sky` (nullopt: not given), settings.replicates 0 chooses.
struct RenderRequest {
    std::string scene;  // glTF path
    RenderSettings settings;
    std::optional<glm::vec3> sky;
    CameraChoice camera;
};

// Where the scene's files come from: disk (recording what was read, for the other ranks of a
// job), or a bundle another rank read.
struct SceneSource {
    const FileBundle* bundle = nullptr;              // read every file from here, not from disk
    std::vector<std::string>* files_read = nullptr;  // disk: the files read, appended
    FileBundle* record = nullptr;                    // disk: their bytes, for the other ranks
};

// The part of a render that the devices need: the settings, their variants as rows, the
// render program's -D options and the launch size, each decided once.
struct RenderPlan {
    RenderSettings settings;
    RenderVariants variants;
    std::string program_options;  // the device adds its own (program.h)
    uint64_t fixed_batch = 0;     // samples per launch with --batch; 0: sized by speed
    // The environment map of settings.env (plan_environment), and the probability in 2^-24 steps
    // that the light strategies choose it (environment_pmf_steps; 0 for the ambient estimators,
    // whose sky it is).
    std::shared_ptr<const EnvironmentLight> environment;
    uint32_t environment_steps = 0;
};

// The scene as loaded and prepared for the plan's devices.
struct PreparedScene {
    Scene scene;
    Camera camera;
    Bvh bvh;
    GpuSceneData gpu;
    double seconds_load = 0;  // reading the glTF file, its buffers and images (decoding them)
};

struct PlannedRender {
    RenderPlan plan;
    PreparedScene scene;
};

// Checks the settings and resolves their variants, the sky and the replicates: what can be
// refused before a scene is read. Throws SettingError.
RenderPlan check_render_settings(RenderSettings settings, const std::optional<glm::vec3>& sky);

// The plan of settings already checked (check_render_settings) for a device scene: its kernel
// options and launch size.
RenderPlan finish_render_plan(RenderPlan plan, const GpuSceneData& scene);

// Reads the environment map of plan.settings.env, if any, from `source` (the disk, recording its
// bytes, or another rank's bundle) and sets how the light strategies choose it for `scene`.
// Throws InputError naming the file.
void plan_environment(RenderPlan& plan, const GpuSceneData& scene, const SceneSource& source);

// Both at once, for a device scene built by the caller (tests, library use); settings.sky and
// sky_light as given.
RenderPlan make_render_plan(const RenderSettings& settings, const GpuSceneData& scene);

// The whole plan: settings checked first, then the scene read from `source`, its materials as
// the materials variant reads them, the camera, the BVH and the device scene. Warnings (an empty
// scene, lights missing for an estimator that needs them) go to `warn`.
PlannedRender plan_render(const RenderRequest& request, const SceneSource& source,
                          const WarningSink& warn);

// Warns, through `warn`, of lights the render cannot show: none at all for an estimator that
// needs lights, or punctual lights that the estimator cannot see (delta lights: no direction
// drawn on the hemisphere finds one), naming the estimator and how many.
void warn_unseen_lights(const std::string& scene_path, const RenderPlan& plan,
                        const GpuSceneData& scene, const WarningSink& warn);

// The camera `choice` names in `scene`; throws SettingError for an index it does not have.
Camera choose_camera(const Scene& scene, const CameraChoice& choice);

// Reads the scene from `source` (load_gltf or load_gltf_from_bundle).
Scene read_scene(const std::string& path, const SceneSource& source, const WarningSink& warn);

}  // namespace mcrt
