// The environment map as a light of a render (--env): read once per render from the disk or, on
// the other ranks of an MPI job, from the bytes rank 0 read; its texels and sampling CDF laid out
// for the devices (RENDER_ARG_ENVIRONMENT); the probability with which the light strategies
// choose it beside the area lights.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "render/gpu_scene.h"
#include "scene/environment_map.h"
#include "scene/gltf_import.h"

namespace mcrt {

struct EnvironmentLight {
    std::string path;
    EnvironmentMap map;  // scaled by --env-scale
    EnvironmentDistribution distribution;
    float rotate_deg = 0.0f;
    double power_unit_radius = 0.0;  // environment_power(map, 1): × r² for a scene of radius r
};

// Reads the map of `path` × scale, turned by rotate_deg: from `bundle` when given (bytes another
// rank read), else from the disk, appending its bytes to `record` when given. Throws InputError
// naming the file (environment_map.h).
std::shared_ptr<const EnvironmentLight> load_environment_light(const std::string& path, float scale,
                                                               float rotate_deg,
                                                               const FileBundle* bundle,
                                                               FileBundle* record);

// The probability, in 2^-24 steps, that the light strategies choose the environment beside the
// area lights of `scene` for light selection `selection`: all of it without area lights; else
// 1/(N + 1) for uniform, and for power, alias and tree the environment's power against the area
// lights' total (the tree splits at its root as pbrt-v4 keeps infinite lights beside its
// BVHLightSampler, but by power), each side at least one step.
uint32_t environment_pmf_steps(const EnvironmentLight& env, const GpuSceneData& scene,
                               LightSelection selection);

// What RENDER_ARG_ENVIRONMENT holds: the texels' RGB (3 per texel, row 0 at the zenith) followed
// by the texel CDF (width·height + 1 entries).
std::vector<float> environment_words(const EnvironmentLight& env);

}  // namespace mcrt
