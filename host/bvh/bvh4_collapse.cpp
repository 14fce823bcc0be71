// Collapse of the binary SAH BVH into the 4-wide BVH the kernels traverse (Wald, Benthin, Boulos
// 2008, "Getting rid of packets"; Embree's BVH4 builders collapse a binary SAH tree the
// same way): same leaves, same triangle order, about half the depth.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "common/error.h"

namespace mcrt {
namespace {

// Empty slots: inverted and finite, as kernels may assume no infinities (see Bvh4Node).
constexpr float kHuge = 1e30f;

uint32_t first_of(const gpu::BvhNode& n) { return gpu::as_uint(n.lo.w); }
uint32_t count_of(const gpu::BvhNode& n) { return gpu::as_uint(n.hi.w); }

// Surface area in double, 0 for an inverted (empty) box (PBRT 3rd ed. 2.1.3).
double area(const float lo[3], const float hi[3]) {
    double d[3];
    for (int k = 0; k < 3; ++k) {
        d[k] = double(hi[k]) - double(lo[k]);
        if (!(d[k] >= 0.0)) return 0.0;
    }
    return 2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

double node_area(const gpu::BvhNode& n) {
    const float lo[3] = {n.lo.x, n.lo.y, n.lo.z}, hi[3] = {n.hi.x, n.hi.y, n.hi.z};
    return area(lo, hi);
}

gpu::Bvh4Node empty_node() {
    gpu::Bvh4Node n{};
    n.lo_x = n.lo_y = n.lo_z = {kHuge, kHuge, kHuge, kHuge};
    n.hi_x = n.hi_y = n.hi_z = {-kHuge, -kHuge, -kHuge, -kHuge};
    return n;
}

void set_lane(gpu::float4& v, int lane, float f) {
    (lane == 0 ? v.x : lane == 1 ? v.y : lane == 2 ? v.z : v.w) = f;
}

float lane(const gpu::float4& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w; }

void set_slot_box(gpu::Bvh4Node& n, int slot, const gpu::BvhNode& child) {
    set_lane(n.lo_x, slot, child.lo.x);
    set_lane(n.lo_y, slot, child.lo.y);
    set_lane(n.lo_z, slot, child.lo.z);
    set_lane(n.hi_x, slot, child.hi.x);
    set_lane(n.hi_y, slot, child.hi.y);
    set_lane(n.hi_z, slot, child.hi.z);
}

// Area of the union of a 4-wide node's non-empty slots (its own box).
double union_area(const gpu::Bvh4Node& n) {
    float lo[3] = {kHuge, kHuge, kHuge}, hi[3] = {-kHuge, -kHuge, -kHuge};
    for (int s = 0; s < 4; ++s) {
        if (lane(n.lo_x, s) > lane(n.hi_x, s)) continue;  // empty slot
        const float l[3] = {lane(n.lo_x, s), lane(n.lo_y, s), lane(n.lo_z, s)};
        const float h[3] = {lane(n.hi_x, s), lane(n.hi_y, s), lane(n.hi_z, s)};
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], l[k]), hi[k] = std::max(hi[k], h[k]);
    }
    return area(lo, hi);
}

}  // namespace

Bvh4 collapse_to_bvh4(const std::vector<gpu::BvhNode>& nodes, float traversal_cost) {
    if (nodes.empty()) throw RuntimeError("BVH4 collapse: the binary BVH has no root");
    // Only the root of an empty scene is a leaf of count 0; any other count-0 node is inner.
    const bool lone_root = nodes.size() == 1;
    auto is_inner = [&](uint32_t i) { return !lone_root && count_of(nodes[i]) == 0; };

    Bvh4 out;
    out.nodes.reserve(nodes.size() / 3 + 1);  // a 4-wide tree has about a third of the nodes
    out.nodes.push_back(empty_node());
    out.depth = 1;
    if (!is_inner(0)) {
        // A lone leaf (or nothing, in an empty scene) under a root with one used slot.
        if (count_of(nodes[0]) > 0) {
            set_slot_box(out.nodes[0], 0, nodes[0]);
            out.nodes[0].child[0] = first_of(nodes[0]);
            out.nodes[0].count[0] = count_of(nodes[0]);
        }
    } else {
        struct Item {
            uint32_t bvh2, bvh4;
            int level;
        };
        std::vector<Item> stack{{0u, 0u, 1}};
        while (!stack.empty()) {
            const Item item = stack.back();
            stack.pop_back();
            out.depth = std::max(out.depth, item.level);
            // Open the inner child of largest surface area until there are four children.
            uint32_t c[4] = {first_of(nodes[item.bvh2]), first_of(nodes[item.bvh2]) + 1};
            int n = 2;
            while (n < 4) {
                int best = -1;
                double best_area = -1.0;
                for (int j = 0; j < n; ++j) {
                    if (!is_inner(c[j])) continue;
                    const double a = node_area(nodes[c[j]]);
                    if (a > best_area) best = j, best_area = a;
                }
                if (best < 0) break;
                // Its two children take its place, keeping the spatial left-to-right order.
                const uint32_t first = first_of(nodes[c[best]]);
                for (int j = n; j > best + 1; --j) c[j] = c[j - 1];
                c[best] = first;
                c[best + 1] = first + 1;
                ++n;
            }
            for (int s = 0; s < n; ++s) {
                const gpu::BvhNode& child = nodes[c[s]];
                set_slot_box(out.nodes[item.bvh4], s, child);
                if (is_inner(c[s])) {
                    if (out.nodes.size() >= size_t(UINT32_MAX))
                        throw RuntimeError("BVH4 collapse: too many nodes for 32-bit indices");
                    const uint32_t index = uint32_t(out.nodes.size());
                    out.nodes.push_back(empty_node());  // may move out.nodes: index, not ref
                    out.nodes[item.bvh4].child[s] = index;
                    out.nodes[item.bvh4].count[s] = 0;
                    stack.push_back({c[s], index, item.level + 1});
                } else {
                    out.nodes[item.bvh4].child[s] = first_of(child);
                    out.nodes[item.bvh4].count[s] = count_of(child);
                }
            }
        }
    }
    if (out.depth > kMaxBvh4Depth)
        throw RuntimeError("BVH4 collapse: depth " + std::to_string(out.depth) +
                           " exceeds the traversal stack's bound " + std::to_string(kMaxBvh4Depth));

    // SAH cost: each node visit costs traversal_cost, each leaf its packets, weighted by the
    // probability A / A_root that a ray through the root enters it (PBRT 3rd ed. 4.3.2).
    const double root_area = union_area(out.nodes[0]);
    auto ratio = [&](double a) { return root_area > 0.0 ? a / root_area : 1.0; };
    double cost = 0.0;
    for (const gpu::Bvh4Node& node : out.nodes) {
        cost += traversal_cost * ratio(union_area(node));
        for (int s = 0; s < 4; ++s) {
            if (node.count[s] == 0) continue;
            const float lo[3] = {lane(node.lo_x, s), lane(node.lo_y, s), lane(node.lo_z, s)};
            const float hi[3] = {lane(node.hi_x, s), lane(node.hi_y, s), lane(node.hi_z, s)};
            cost += packets_for(node.count[s]) * ratio(area(lo, hi));
        }
    }
    // An empty scene's root is never entered: it costs nothing.
    const gpu::Bvh4Node& root = out.nodes[0];
    const bool empty = lane(root.lo_x, 0) > lane(root.hi_x, 0);
    out.sah_cost = empty ? 0.0 : cost;
    return out;
}

std::vector<gpu::TrianglePacket> pack_leaves(std::vector<gpu::Bvh4Node>& nodes,
                                             const std::vector<gpu::Triangle>& triangles) {
    std::vector<gpu::TrianglePacket> packets;
    packets.reserve(triangles.size() / 2 + 1);
    for (gpu::Bvh4Node& node : nodes) {
        for (int s = 0; s < 4; ++s) {
            const uint32_t first = node.child[s], count = node.count[s];
            if (count == 0) continue;  // inner or empty
            if (size_t(first) + count > triangles.size())
                throw RuntimeError("BVH packets: a leaf's triangles run past the triangle array");
            if (packets.size() + packets_for(count) >= size_t(UINT32_MAX))
                throw RuntimeError("BVH packets: too many packets for 32-bit indices");
            node.child[s] = uint32_t(packets.size());
            for (uint32_t k = 0; k < count; k += MCRT_PACKET_WIDTH) {
                gpu::TrianglePacket p{};  // unused lanes: vertices 0, index MCRT_NO_HIT
                for (int i = 0; i < MCRT_PACKET_WIDTH; ++i) p.index[i] = MCRT_NO_HIT;
                for (uint32_t i = 0; i < MCRT_PACKET_WIDTH && k + i < count; ++i) {
                    const gpu::Triangle& t = triangles[first + k + i];
                    const gpu::float4* v[3] = {&t.p0, &t.p1, &t.p2};
                    for (int j = 0; j < 3; ++j) {
                        set_lane(p.v[3 * j + 0], int(i), v[j]->x);
                        set_lane(p.v[3 * j + 1], int(i), v[j]->y);
                        set_lane(p.v[3 * j + 2], int(i), v[j]->z);
                    }
                    p.index[i] = t.index;
                }
                packets.push_back(p);
            }
        }
    }
    return packets;
}

}  // namespace mcrt
