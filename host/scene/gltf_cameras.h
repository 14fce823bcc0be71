// The camera a glTF node holds, as mcrt's Camera ("Cameras").
#pragma once

#include <tiny_gltf.h>

#include <glm/glm.hpp>
#include <optional>

#include "scene/gltf_diagnostics.h"
#include "scene/scene.h"

namespace mcrt::gltf {

// Camera `camera_index` of node `node_index`, whose world transform is `world`; none for an
// orthographic camera (warned once). Its name: the camera's, else the node's, else "camera N".
std::optional<Camera> read_camera(const tinygltf::Model& model, int camera_index,
                                  const glm::dmat4& world, int node_index, Diagnostics& diag);

}  // namespace mcrt::gltf
