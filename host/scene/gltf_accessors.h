// The vertex data of a primitive from its accessors ("Accessors"): positions and indices, each
// accessor, buffer view and buffer checked before a byte is read (tinygltf checks none).
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "scene/gltf_diagnostics.h"

namespace mcrt::gltf {

// POSITION: VEC3 of floats ("Meshes", attribute table), or of (normalized) 8/16-bit integers as
// KHR_mesh_quantization allows. Every component is finite and within kMaxCoordinate.
std::vector<glm::dvec3> read_positions(const tinygltf::Model& model, int index,
                                       const std::string& referrer, const Diagnostics& diag);

// Indices: SCALAR of unsigned bytes, shorts or ints, each < the POSITION count ("Meshes").
std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, size_t vertex_count,
                                   const std::string& referrer, const Diagnostics& diag);

}  // namespace mcrt::gltf
