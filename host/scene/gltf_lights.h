// KHR_lights_punctual: the light a glTF node holds, as mcrt's PunctualLight.
#pragma once

#include <tiny_gltf.h>

#include <glm/glm.hpp>

#include "scene/gltf_diagnostics.h"
#include "scene/punctual_light.h"

namespace mcrt::gltf {

// The light node `node_index` names in its KHR_lights_punctual extension, placed by `world`.
// Hostile values (negative, infinite or NaN color or intensity, cone angles out of order or past
// π/2, an unknown type, an index out of range, a degenerate transform) fail with one line; a
// `range` is warned about once and ignored.
PunctualLight read_punctual_light(const tinygltf::Model& model, const tinygltf::Value& extension,
                                  const glm::dmat4& world, int node_index, Diagnostics& diag);

}  // namespace mcrt::gltf
