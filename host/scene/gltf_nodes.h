// The node hierarchy of a glTF model: which nodes a render starts from, how far they expand, and
// the walk that gives each node instance its world transform.
#pragma once

#include <tiny_gltf.h>

#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "scene/gltf_diagnostics.h"

namespace mcrt::gltf {

struct RootNodes {
    std::vector<int> nodes;
    std::string element;  // who lists them, for errors
};

// The `scene` property's scene, else scene 0 ("Scenes"); a file without scenes renders its
// root nodes (those no node lists as a child).
RootNodes root_nodes(const tinygltf::Model& model, const Diagnostics& diag);

// Node instances and triangles each root expands to, counted bottom-up per node (a shared
// subtree once) before anything is expanded, so an exponential hierarchy is refused at once.
// Triangle counts are upper bounds from the accessor counts; cycles are left to traverse().
void check_expansion(const tinygltf::Model& model, const RootNodes& roots, const Diagnostics& diag);

// Called once per node instance with the node's index and its world transform.
using NodeVisitor = std::function<void(int node, const glm::dmat4& world)>;

// Depth-first, pre-order, children in order ("Nodes and Hierarchy"). An explicit stack, so deep
// hierarchies cannot overflow the call stack; a node already on the path is a cycle, a node met
// again elsewhere is a shared subtree and is instanced. A node's local transform
// ("Transformations": a column-major `matrix`, or T·R·S) is checked before it is visited.
void traverse(const tinygltf::Model& model, const RootNodes& roots, Diagnostics& diag,
              const NodeVisitor& visit);

}  // namespace mcrt::gltf
