// The vertex data of a primitive from its accessors ("Accessors"): positions, indices and the
// attributes textures read, each accessor, buffer view and buffer checked before a byte is read
// (tinygltf checks none).
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

// The other vertex attributes have exactly `vertex_count` (POSITION's count) finite elements
// ("Meshes": all attribute accessors of a primitive have the same count). `attribute` names the
// attribute in messages.

// TEXCOORD_n: VEC2 of floats or of normalized unsigned bytes or shorts ("Meshes", attribute
// table); KHR_mesh_quantization adds signed and unnormalized 8/16-bit integers.
std::vector<glm::dvec2> read_texcoords(const tinygltf::Model& model, int index, size_t vertex_count,
                                       const std::string& attribute, const std::string& referrer,
                                       const Diagnostics& diag);

// NORMAL: VEC3 of floats ("Meshes", attribute table), or of normalized bytes or shorts
// (KHR_mesh_quantization). Returned as stored: unit length is the file's promise, not checked.
std::vector<glm::dvec3> read_normals(const tinygltf::Model& model, int index, size_t vertex_count,
                                     const std::string& referrer, const Diagnostics& diag);

// TANGENT: VEC4 of floats ("Meshes", attribute table), or of normalized bytes or shorts
// (KHR_mesh_quantization); xyz the tangent, w the handedness (±1). Returned as stored.
std::vector<glm::dvec4> read_tangents(const tinygltf::Model& model, int index, size_t vertex_count,
                                      const std::string& referrer, const Diagnostics& diag);

}  // namespace mcrt::gltf
