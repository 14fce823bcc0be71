// Bounding volume hierarchy: binned SAH build on the host, flattened for the device.
#pragma once

#include <vector>

#include "scene/scene.h"
#include "shared_types.h"

namespace mcrt {

// Guaranteed bound on BvhStats::depth, the number of nodes on the longest root-to-leaf path
// (a lone root leaf has depth 1). build_bvh switches from SAH to median splits wherever an SAH
// split would leave a child too many triangles to fit in the remaining levels, so no tree is
// deeper than this: a traversal stack of 64 entries (push both children, or push the far one)
// can never overflow. Median splits need only 1 + ceil(log2(ceil(N / max_leaf_size))) ≤ 33
// levels for any 32-bit triangle count, so the bound always holds.
constexpr int kMaxBvhDepth = 60;

struct BvhBuildOptions {
    int bins = 16;             // SAH bins per axis (Wald 2007, "On fast construction of SAH BVHs")
    int max_leaf_size = 8;     // a leaf never holds more triangles than this
    float traversal_cost = 1.0f;  // SAH cost of visiting an inner node, relative to a triangle test
};

struct BvhStats {
    double build_seconds = 0;
    double sah_cost = 0;       // expected cost per ray, in triangle tests (PBRT 4.3.2)
    int depth = 0;             // nodes on the longest root-to-leaf path, ≤ kMaxBvhDepth
    size_t inner_nodes = 0, leaves = 0;
    size_t bytes = 0;          // nodes + leaf-ordered triangles
};

struct Bvh {
    std::vector<gpu::BvhNode> nodes;       // nodes[0] is the root
    std::vector<gpu::Triangle> triangles;  // in leaf order
    BvhStats stats;
};

// Builds over every triangle of the scene (degenerate ones included: they are never hit).
Bvh build_bvh(const Scene& scene, const BvhBuildOptions& options = {});

}  // namespace mcrt
