// Bounding volume hierarchy: binned SAH build on the host, flattened for the device.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"
#include "shared_types.h"

namespace mcrt {

// Guaranteed bound on BvhStats::depth, the number of nodes on the longest root-to-leaf path
// (a lone root leaf has depth 1). build_bvh switches from SAH to median splits wherever an SAH
// split would leave a child too many triangles to fit in the remaining levels, so no tree is
// deeper than this. Median splits need only 1 + ceil(log2(ceil(N / max_leaf_size))) ≤ 33
// levels for any 32-bit triangle count, so the bound always holds. The 4-wide tree the device
// traverses has at most kMaxBvhDepth - 1 inner nodes on a path (kMaxBvh4Depth), and its traversal
// pushes at most 3 children per inner node: a stack of 3 · kMaxBvh4Depth entries never overflows.
constexpr int kMaxBvhDepth = MCRT_BVH_MAX_DEPTH;
constexpr int kMaxBvh4Depth = MCRT_BVH4_MAX_DEPTH;

struct BvhBuildOptions {
    int bins = 16;          // SAH bins per axis (Wald 2007, "On fast construction of SAH BVHs")
    int max_leaf_size = 8;  // a leaf never holds more triangles than this
    // SAH cost of visiting an inner node, relative to testing one TrianglePacket (up to 4
    // triangles at once: a leaf of N triangles costs ceil(N / 4), as in Embree's SAH).
    float traversal_cost = 1.0f;
};

struct BvhStats {
    double build_seconds = 0;
    double sah_cost = 0;  // expected cost per ray, in packet tests (PBRT 4.3.2)
    int depth = 0;        // nodes on the longest root-to-leaf path, ≤ kMaxBvhDepth
    size_t inner_nodes = 0, leaves = 0;
    size_t packets = 0;  // TrianglePackets (ceil(N / 4) per leaf of N triangles)
    size_t bytes = 0;    // what the device holds: 4-wide nodes, packets, a TriangleInfo per lane
    double collapse_seconds = 0;  // of build_seconds, the BVH2 → BVH4 collapse and packing
    int depth4 = 0;               // Bvh4Nodes on the longest root-to-leaf path, ≤ kMaxBvh4Depth
    double sah_cost4 = 0;         // SAH cost of the 4-wide tree (a node visit costs traversal_cost)
};

struct Bvh {
    std::vector<gpu::BvhNode> nodes;           // binary SAH tree; nodes[0] is the root
    std::vector<gpu::Bvh4Node> nodes4;         // the same leaves under 4-wide nodes, for the device
    std::vector<gpu::TrianglePacket> packets;  // nodes4's leaves, four triangles per packet
    std::vector<gpu::Triangle> triangles;  // in leaf order (host only: the device reads packets)
    BvhStats stats;
};

// Builds over every triangle of the scene (degenerate ones included: they are never hit): the
// binary SAH tree, then its collapse into the 4-wide tree, then its leaves' packets.
Bvh build_bvh(const Scene& scene, const BvhBuildOptions& options = {});

// Collapses a binary BVH into a 4-wide one with the same leaves: each 4-wide node takes the
// children of a binary inner node, then repeatedly replaces its inner child of largest surface
// area by that child's two children until it has four (Wald, Benthin, Boulos 2008;
// Embree's BVH4 collapse). Nodes are laid out depth-first, nodes[0] the root.
// Leaf slots hold the first triangle in leaf order and the count, as in the binary tree.
struct Bvh4 {
    std::vector<gpu::Bvh4Node> nodes;
    int depth = 0;        // Bvh4Nodes on the longest root-to-leaf path
    double sah_cost = 0;  // node visits cost traversal_cost, leaves their packet count
};
Bvh4 collapse_to_bvh4(const std::vector<gpu::BvhNode>& nodes, float traversal_cost);

// Packs each leaf's triangles (leaf-ordered `triangles`) into TrianglePackets and points the
// leaf slot at its first packet instead of its first triangle (see Bvh4Node).
std::vector<gpu::TrianglePacket> pack_leaves(std::vector<gpu::Bvh4Node>& nodes,
                                             const std::vector<gpu::Triangle>& triangles);

// Packet tests for a leaf of `count` triangles.
constexpr uint32_t packets_for(uint32_t count) {
    return (count + MCRT_PACKET_WIDTH - 1) / MCRT_PACKET_WIDTH;
}

}  // namespace mcrt
