// The light tree of --light-select tree: a bounding hierarchy over the emissive triangles whose
// nodes carry power, a box and a cone of emitting normals, so that the kernels can choose a
// light in proportion to an importance that depends on the shading point
// (kernels/lights/light_tree.cl; Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights
// with Adaptive Tree Splitting"; pbrt-v4's BVHLightSampler).
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "shared_types.h"

namespace mcrt {

struct LightTree {
    std::vector<gpu::LightTreeNode> nodes;  // nodes[0] the root; empty when no light has power
    // Per light: its path from the root (bits 2d, 2d + 1: the slot taken at depth d) and the
    // path's number of nodes, 0 for a light outside the tree (zero power): what the kernels'
    // pmf twin walks, uploaded after the nodes.
    std::vector<gpu::LightTreePath> paths;
};

// A light of the tree that is not a triangle (a punctual light): the box of its position (a
// directional light: of the scene), its cone of emission directions about `axis` of half-angle
// θ_o and the spread θ_e beyond it, and the power its importance is weighed by (pbrt-v4's
// PointLight::Bounds, SpotLight::Bounds: 4πI for both).
struct LightTreeItem {
    glm::dvec3 lo{0.0}, hi{0.0};
    glm::dvec3 axis{0.0, 0.0, 1.0};
    double cos_o = -1.0, cos_e = 0.0;
    double phi = 0.0;
};

// Builds the tree over `lights` (vertices and MATERIAL_DOUBLE_SIDED from gpu::Light) weighted by
// `powers` (one per light, >= 0; zero-power lights are left out and never chosen). A binary
// tree top-down, binned (12 buckets per axis) with pbrt-v4's surface-area-orientation cost:
// power × the orientation measure M_Ω of the cone × surface area × the box's aspect penalty,
// its subtrees built on `threads` threads (0: one per core; the tree is the same for any
// number); then collapsed two levels to a node of four slots, a slot holding one light or a
// node. No path is longer than MCRT_LIGHT_TREE_MAX_DEPTH nodes.
// `more` are lights lights.size() + k after the triangles (their inclusion, as every light's,
// decided by `powers`, which has an entry for each); a tree without them is the same as before.
LightTree build_light_tree(const std::vector<gpu::Light>& lights, const std::vector<double>& powers,
                           int threads = 0, const std::vector<LightTreeItem>& more = {});

// The tree as the kernels read it from the selection's buffer: its nodes (at least one), then
// one path per light (RENDER_ARG_LIGHT_SELECTION), as 32-bit words.
std::vector<uint32_t> light_tree_words(const LightTree& tree);

}  // namespace mcrt
