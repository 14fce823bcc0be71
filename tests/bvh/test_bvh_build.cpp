// Binned SAH BVH build and its 4-wide collapse: structure of both flat layouts, SAH costs, and
// closest hits of reference CPU traversals against brute force (as tinybvh validates each layout
// against a reference tracer).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

#include "bvh/bvh.h"
#include "common/error.h"

using namespace mcrt;

namespace {

uint32_t float_bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

uint32_t node_first(const gpu::BvhNode& n) { return float_bits(n.lo.w); }
uint32_t node_count(const gpu::BvhNode& n) { return float_bits(n.hi.w); }

struct Box {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};
    void grow(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    double area() const {
        glm::dvec3 d = glm::dvec3(hi) - glm::dvec3(lo);
        if (d.x < 0 || d.y < 0 || d.z < 0) return 0.0;
        return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    }
};

Box box_of(const gpu::BvhNode& n) {
    Box b;
    b.lo = {n.lo.x, n.lo.y, n.lo.z};
    b.hi = {n.hi.x, n.hi.y, n.hi.z};
    return b;
}

bool inside(const Box& inner, const Box& outer) {
    return glm::all(glm::greaterThanEqual(inner.lo, outer.lo)) &&
           glm::all(glm::lessThanEqual(inner.hi, outer.hi));
}

bool same_box(const Box& a, const Box& b) { return a.lo == b.lo && a.hi == b.hi; }

Scene make_scene(std::vector<glm::vec3> positions, uint32_t materials = 3) {
    Scene s;
    s.positions = std::move(positions);
    s.triangle_material.resize(s.positions.size() / 3);
    for (size_t t = 0; t < s.triangle_material.size(); ++t)
        s.triangle_material[t] = uint32_t((t * 7) % materials);
    s.materials.resize(materials);
    return s;
}

// Triangles of edge ~size centred uniformly in [0,1]³ (PBRT's "random triangle soup").
Scene random_soup(size_t n, float size, uint32_t seed, glm::vec3 offset = glm::vec3(0.0f)) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), v(-1.0f, 1.0f);
    std::vector<glm::vec3> p;
    for (size_t t = 0; t < n; ++t) {
        glm::vec3 c(u(rng), u(rng), u(rng));
        for (int i = 0; i < 3; ++i)
            p.push_back(offset + c + size * glm::vec3(v(rng), v(rng), v(rng)));
    }
    return make_scene(std::move(p));
}

// A flat nx × ny grid of unit quads in z = 0, two triangles each.
Scene grid(int nx, int ny) {
    std::vector<glm::vec3> p;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            glm::vec3 a(i, j, 0), b(i + 1, j, 0), c(i + 1, j + 1, 0), d(i, j + 1, 0);
            p.insert(p.end(), {a, b, c, a, c, d});
        }
    return make_scene(std::move(p));
}

Scene coincident(size_t n) {
    std::vector<glm::vec3> p;
    for (size_t t = 0; t < n; ++t)
        p.insert(p.end(), {{0.2f, 0.1f, 0.3f}, {1.1f, 0.4f, 0.2f}, {0.5f, 1.3f, 0.6f}});
    return make_scene(std::move(p));
}

// A soup with zero-area triangles mixed in: points, repeated vertices, collinear vertices.
Scene with_degenerates(size_t n, uint32_t seed) {
    Scene s = random_soup(n, 0.03f, seed);
    std::mt19937 rng(seed + 1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (size_t t = 0; t < n; t += 3) {
        glm::vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
        glm::vec3* tri = &s.positions[3 * t];
        if (t % 9 == 0)
            tri[0] = tri[1] = tri[2] = a;  // a point
        else if (t % 9 == 3)
            tri[0] = a, tri[1] = a, tri[2] = b;  // two equal vertices
        else
            tri[0] = a, tri[1] = 0.5f * (a + b), tri[2] = b;  // collinear
    }
    return s;
}

// Small triangles at distances spread log-uniformly over 60 decades: equal-width bins peel off
// the far ones level after level, and plain binned SAH goes 70+ levels deep on it.
Scene log_uniform_scatter(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> decade(-30.0f, 30.0f), u(0.0f, 1.0f);
    std::vector<glm::vec3> p;
    for (size_t t = 0; t < n; ++t) {
        float x = std::pow(10.0f, decade(rng)), y = x * u(rng), z = x * u(rng), e = 0.01f * x;
        p.insert(p.end(), {{x, y, z}, {x + e, y, z}, {x, y + e, z}});
    }
    return make_scene(std::move(p));
}

// A tessellated sphere with a noisy radius plus small random triangles: 2·rings·segments + extra.
Scene noisy_sphere_and_soup(int rings, int segments, size_t extra, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), v(-1.0f, 1.0f);
    const float pi = 3.14159265f;
    std::vector<glm::vec3> grid_points(size_t(rings + 1) * size_t(segments + 1));
    for (int j = 0; j <= rings; ++j)
        for (int i = 0; i <= segments; ++i) {
            float theta = pi * j / rings, phi = 2 * pi * (i % segments) / segments;
            float r = 1.0f + 0.05f * std::sin(7 * theta) * std::cos(5 * phi) + 0.01f * u(rng);
            grid_points[size_t(j) * (segments + 1) + i] =
                r * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                              std::sin(theta) * std::sin(phi));
        }
    std::vector<glm::vec3> p;
    p.reserve(3 * (2 * size_t(rings) * segments + extra));
    for (int j = 0; j < rings; ++j)
        for (int i = 0; i < segments; ++i) {
            auto at = [&](int jj, int ii) { return grid_points[size_t(jj) * (segments + 1) + ii]; };
            p.insert(p.end(), {at(j, i), at(j + 1, i), at(j + 1, i + 1), at(j, i), at(j + 1, i + 1),
                               at(j, i + 1)});
        }
    for (size_t t = 0; t < extra; ++t) {
        glm::vec3 c(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
        for (int k = 0; k < 3; ++k) p.push_back(c + 0.01f * glm::vec3(v(rng), v(rng), v(rng)));
    }
    return make_scene(std::move(p), 5);
}

// SAH cost recomputed from the flat nodes (PBRT 4.3.2).
double sah_cost(const Bvh& bvh, float traversal_cost) {
    double root = box_of(bvh.nodes[0]).area(), cost = 0.0;
    for (const gpu::BvhNode& n : bvh.nodes) {
        double ratio = root > 0 ? box_of(n).area() / root : 1.0;
        bool inner = node_count(n) == 0 && bvh.nodes.size() > 1;
        cost += (inner ? traversal_cost : double(packets_for(node_count(n)))) * ratio;
    }
    return cost;
}

float lane(const gpu::float4& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w; }

// Box of slot s of a 4-wide node.
Box slot_box(const gpu::Bvh4Node& n, int s) {
    Box b;
    b.lo = {lane(n.lo_x, s), lane(n.lo_y, s), lane(n.lo_z, s)};
    b.hi = {lane(n.hi_x, s), lane(n.hi_y, s), lane(n.hi_z, s)};
    return b;
}

bool is_empty_slot(const gpu::Bvh4Node& n, int s) {
    const Box b = slot_box(n, s);
    return n.count[s] == 0 && n.child[s] == 0 && b.lo == glm::vec3(1e30f) &&
           b.hi == glm::vec3(-1e30f);
}

// Every invariant of the 4-wide tree the kernels traverse: each node reached once from the
// root, each triangle in exactly one leaf, the leaves those of the binary tree, every slot box
// tight around its subtree, empty slots inverted, the depth within the traversal stack's bound.
void validate4(const Bvh& bvh, const BvhBuildOptions& options) {
    const size_t n = bvh.triangles.size();
    REQUIRE(!bvh.nodes4.empty());
    std::vector<int> reached(bvh.nodes4.size(), 0), covered(n, 0),
        packet_uses(bvh.packets.size(), 0);
    std::vector<std::pair<uint32_t, uint32_t>> leaves4, leaves2;
    std::vector<uint32_t> leaf_position(n, UINT32_MAX);  // of each scene triangle
    for (uint32_t i = 0; i < n; ++i)
        if (bvh.triangles[i].index < n) leaf_position[bvh.triangles[i].index] = i;
    size_t problems = 0, infinite = 0, lonely = 0;
    int depth = 0;
    double cost = 0.0, root_area = 0.0;
    // (node, level), with the box its parent's slot gives it (the root: the union of its slots).
    struct Item {
        uint32_t node;
        int level;
        Box box;
        bool from_parent;
    };
    std::vector<Item> stack{{0u, 1, Box{}, false}};
    while (!stack.empty()) {
        const Item item = stack.back();
        stack.pop_back();
        if (++reached[item.node] > 1) continue;
        depth = std::max(depth, item.level);
        const gpu::Bvh4Node& node = bvh.nodes4[item.node];
        Box u;
        int used = 0;
        for (int s = 0; s < 4; ++s) {
            const Box b = slot_box(node, s);
            for (int k = 0; k < 3; ++k)
                infinite += !std::isfinite(b.lo[k]) + !std::isfinite(b.hi[k]);
            if (is_empty_slot(node, s)) continue;
            ++used;
            if (!glm::all(glm::lessThanEqual(b.lo, b.hi))) ++problems;
            u.grow(b.lo), u.grow(b.hi);
            if (node.count[s] == 0) {
                if (node.child[s] <= item.node || node.child[s] >= bvh.nodes4.size()) {
                    ++problems;
                    continue;
                }
                stack.push_back({node.child[s], item.level + 1, b, true});
                continue;
            }
            // The slot names the leaf's first packet; its lanes hold the leaf's triangles in leaf
            // order, each named by its scene index (the closest hit's tie-break).
            const uint32_t packet = node.child[s], count = node.count[s];
            if (count > uint32_t(options.max_leaf_size) ||
                size_t(packet) + packets_for(count) > bvh.packets.size()) {
                ++problems;
                continue;
            }
            // The leaf's triangles are a run of the leaf-ordered array.
            const uint32_t named = bvh.packets[packet].index[0];
            const uint32_t first = named < n ? leaf_position[named] : UINT32_MAX;
            if (size_t(first) + count > n) {
                ++problems;
                continue;
            }
            for (uint32_t k = 0; k < packets_for(count); ++k) {
                const gpu::TrianglePacket& p = bvh.packets[packet + k];
                ++packet_uses[packet + k];
                for (uint32_t i = 0; i < MCRT_PACKET_WIDTH; ++i) {
                    const uint32_t j = k * MCRT_PACKET_WIDTH + i;  // the leaf's j-th triangle
                    if (j >= count) {  // unused lanes: no triangle, vertices 0
                        if (p.index[i] != 0xffffffffu) ++problems;
                        for (int v = 0; v < 9; ++v) problems += lane(p.v[v], int(i)) != 0.0f;
                        continue;
                    }
                    if (p.index[i] != bvh.triangles[first + j].index) ++problems;
                    const gpu::Triangle& t = bvh.triangles[first + j];
                    const gpu::float4* q[3] = {&t.p0, &t.p1, &t.p2};
                    for (int v = 0; v < 3; ++v)
                        problems += lane(p.v[3 * v], int(i)) != q[v]->x ||
                                    lane(p.v[3 * v + 1], int(i)) != q[v]->y ||
                                    lane(p.v[3 * v + 2], int(i)) != q[v]->z;
                }
            }
            leaves4.push_back({first, count});
            Box tight;
            for (uint32_t i = first; i < first + count; ++i) {
                ++covered[i];
                const gpu::Triangle& t = bvh.triangles[i];
                for (const gpu::float4& q : {t.p0, t.p1, t.p2}) tight.grow({q.x, q.y, q.z});
            }
            if (!same_box(tight, b)) ++problems;
        }
        // A child's slot box is exactly the union of its own slots; inner nodes use ≥ 2 slots.
        if (item.from_parent && (!same_box(u, item.box) || used < 2)) ++problems;
        if (!item.from_parent) root_area = u.area();  // the root comes first
        lonely += item.from_parent && used < 2;
        // SAH cost (PBRT 4.3.2): a node visit costs traversal_cost, a leaf its packets.
        auto weight = [&](const Box& b) { return root_area > 0 ? b.area() / root_area : 1.0; };
        if (used > 0) cost += options.traversal_cost * weight(u);
        for (int s = 0; s < 4; ++s)
            if (node.count[s] > 0) cost += packets_for(node.count[s]) * weight(slot_box(node, s));
    }
    for (const gpu::BvhNode& node : bvh.nodes)
        if (node_count(node) > 0) leaves2.push_back({node_first(node), node_count(node)});
    std::sort(leaves4.begin(), leaves4.end());
    std::sort(leaves2.begin(), leaves2.end());
    CHECK(problems == 0);
    CHECK(lonely == 0);
    CHECK(infinite == 0);
    CHECK(leaves4 == leaves2);
    CHECK(std::count(reached.begin(), reached.end(), 1) == std::ptrdiff_t(bvh.nodes4.size()));
    CHECK(std::count(covered.begin(), covered.end(), 1) == std::ptrdiff_t(n));
    CHECK(std::count(packet_uses.begin(), packet_uses.end(), 1) ==
          std::ptrdiff_t(bvh.packets.size()));
    CHECK(bvh.stats.packets == bvh.packets.size());
    CHECK(depth == bvh.stats.depth4);
    CHECK(depth <= kMaxBvh4Depth);
    CHECK(depth <= std::max(1, bvh.stats.depth - 1));
    CHECK(bvh.stats.sah_cost4 == Approx(cost).epsilon(1e-6));
    CHECK(bvh.stats.bytes ==
          bvh.nodes4.size() * sizeof(gpu::Bvh4Node) +
              bvh.packets.size() * (sizeof(gpu::TrianglePacket) + 4 * sizeof(gpu::TriangleInfo)));
    if (n == 0) {
        for (int s = 0; s < 4; ++s) CHECK(is_empty_slot(bvh.nodes4[0], s));
        CHECK(bvh.stats.sah_cost4 == 0.0);
    }
}

// Every invariant of the flat layout that the kernels rely on.
void validate(const Scene& scene, const Bvh& bvh, const BvhBuildOptions& options) {
    const size_t n = scene.triangle_count();
    REQUIRE(!bvh.nodes.empty());
    REQUIRE(bvh.triangles.size() == n);

    // Every scene triangle exactly once, with its material and vertices.
    std::vector<int> seen(n, 0);
    size_t bad_triangles = 0;
    for (const gpu::Triangle& tri : bvh.triangles) {
        uint32_t id = tri.index;
        if (id >= n) {
            ++bad_triangles;
            continue;
        }
        ++seen[id];
        const glm::vec3* p = &scene.positions[3 * size_t(id)];
        bool ok = tri.material == scene.triangle_material[id] &&
                  glm::vec3(tri.p0.x, tri.p0.y, tri.p0.z) == p[0] &&
                  glm::vec3(tri.p1.x, tri.p1.y, tri.p1.z) == p[1] &&
                  glm::vec3(tri.p2.x, tri.p2.y, tri.p2.z) == p[2];
        if (!ok) ++bad_triangles;
    }
    REQUIRE(bad_triangles == 0);
    REQUIRE(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(n));

    // Walk the tree left child first: each node reached once, boxes nested and tight, leaves
    // covering [0, n) once, and children pairs numbered in visiting order (a depth-first layout).
    std::vector<int> reached(bvh.nodes.size(), 0), covered(n, 0);
    size_t problems = 0, inner = 0, leaves = 0, not_depth_first = 0;
    uint32_t next_pair = 1;
    int depth = 0;
    std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
    while (!stack.empty()) {
        auto [index, level] = stack.back();
        stack.pop_back();
        ++reached[index];
        const gpu::BvhNode& node = bvh.nodes[index];
        const Box box = box_of(node);
        const uint32_t first = node_first(node), count = node_count(node);
        if (count == 0 && n > 0) {
            ++inner;
            if (first <= index || size_t(first) + 1 >= bvh.nodes.size()) {
                ++problems;
                continue;
            }
            if (first != next_pair) ++not_depth_first;
            next_pair = first + 2;
            Box l = box_of(bvh.nodes[first]), r = box_of(bvh.nodes[first + 1]), u = l;
            u.grow(r.lo), u.grow(r.hi);
            if (!inside(l, box) || !inside(r, box) || !same_box(u, box)) ++problems;
            stack.push_back({first + 1, level + 1});
            stack.push_back({first, level + 1});
        } else {
            ++leaves;
            depth = std::max(depth, level);
            if (count > uint32_t(options.max_leaf_size) || size_t(first) + count > n) {
                ++problems;
                continue;
            }
            Box tight;
            for (uint32_t i = first; i < first + count; ++i) {
                ++covered[i];
                const gpu::Triangle& t = bvh.triangles[i];
                for (const gpu::float4& q : {t.p0, t.p1, t.p2}) tight.grow({q.x, q.y, q.z});
            }
            if (count > 0 && !same_box(tight, box)) ++problems;
        }
    }
    CHECK(problems == 0);
    CHECK(not_depth_first == 0);
    CHECK(std::count(reached.begin(), reached.end(), 1) == std::ptrdiff_t(bvh.nodes.size()));
    CHECK(std::count(covered.begin(), covered.end(), 1) == std::ptrdiff_t(n));
    CHECK(depth <= kMaxBvhDepth);
    CHECK(depth == bvh.stats.depth);
    CHECK(bvh.stats.inner_nodes == inner);
    CHECK(bvh.stats.leaves == leaves);
    CHECK(bvh.stats.sah_cost == Approx(sah_cost(bvh, options.traversal_cost)).epsilon(1e-6));
    size_t infinite = 0;  // kernels built with -cl-fast-relaxed-math assume no infinities
    for (const gpu::BvhNode& node : bvh.nodes)
        for (float f : {node.lo.x, node.lo.y, node.lo.z, node.hi.x, node.hi.y, node.hi.z})
            infinite += !std::isfinite(f);
    CHECK(infinite == 0);
    validate4(bvh, options);
}

struct Ray {
    glm::vec3 o, d;
};

// Möller–Trumbore; t in (0, t_max) or -1. Both tracers use it on the same floats.
float intersect(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                float t_max) {
    glm::vec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(ray.d, e2);
    float det = glm::dot(e1, pv);
    if (det == 0.0f) return -1.0f;
    float inv = 1.0f / det;
    glm::vec3 tv = ray.o - p0;
    float u = glm::dot(tv, pv) * inv;
    if (u < 0.0f || u > 1.0f) return -1.0f;
    glm::vec3 qv = glm::cross(tv, e1);
    float v = glm::dot(ray.d, qv) * inv;
    if (v < 0.0f || u + v > 1.0f) return -1.0f;
    float t = glm::dot(e2, qv) * inv;
    return (t > 0.0f && t < t_max) ? t : -1.0f;
}

struct Hit {
    float t = std::numeric_limits<float>::infinity();
    int64_t triangle = -1;  // scene index
};

Hit brute_force(const Scene& s, const Ray& ray) {
    Hit h;
    for (size_t i = 0; i < s.triangle_count(); ++i) {
        float t =
            intersect(ray, s.positions[3 * i], s.positions[3 * i + 1], s.positions[3 * i + 2], h.t);
        if (t > 0.0f) h = {t, int64_t(i)};
    }
    return h;
}

// Reference traversal of the flat layout: stack, slab test with tmax scaled by 1 + 2γ₃ so that
// rounding never culls a box the ray touches (PBRT 3rd ed. 3.9.2).
Hit traverse(const Bvh& bvh, const Ray& ray, bool& overflow) {
    const float gamma3 = 3 * 0x1p-24f / (1 - 3 * 0x1p-24f);
    const glm::vec3 inv_d = 1.0f / ray.d;
    Hit h;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const gpu::BvhNode& node = bvh.nodes[stack[--top]];
        glm::vec3 t0 = (glm::vec3(node.lo.x, node.lo.y, node.lo.z) - ray.o) * inv_d;
        glm::vec3 t1 = (glm::vec3(node.hi.x, node.hi.y, node.hi.z) - ray.o) * inv_d;
        glm::vec3 tn = glm::min(t0, t1), tf = glm::max(t0, t1);
        float t_near = std::max(std::max(tn.x, tn.y), std::max(tn.z, 0.0f));
        float t_far = std::min(std::min(tf.x, tf.y), std::min(tf.z, h.t)) * (1 + 2 * gamma3);
        if (t_near > t_far) continue;
        uint32_t first = node_first(node), count = node_count(node);
        if (count == 0 && bvh.nodes.size() > 1) {
            if (top + 2 > 64) {
                overflow = true;
                return h;
            }
            stack[top++] = first + 1;
            stack[top++] = first;
            continue;
        }
        for (uint32_t i = first; i < first + count; ++i) {
            const gpu::Triangle& tri = bvh.triangles[i];
            float t = intersect(ray, {tri.p0.x, tri.p0.y, tri.p0.z}, {tri.p1.x, tri.p1.y, tri.p1.z},
                                {tri.p2.x, tri.p2.y, tri.p2.z}, h.t);
            if (t > 0.0f) h = {t, int64_t(tri.index)};
        }
    }
    return h;
}

// Reference traversal of the 4-wide tree as the kernels test it: near and far planes chosen by
// the ray's signs (so that inverted empty slots are rejected), exit scaled by 1 + 2γ₃.
Hit traverse4(const Bvh& bvh, const Ray& ray, bool& overflow) {
    const float gamma3 = 3 * 0x1p-24f / (1 - 3 * 0x1p-24f);
    const glm::vec3 inv_d = 1.0f / ray.d;
    Hit h;
    std::vector<uint32_t> stack{0u};
    while (!stack.empty()) {
        const gpu::Bvh4Node& node = bvh.nodes4[stack.back()];
        stack.pop_back();
        for (int s = 0; s < 4; ++s) {
            const Box b = slot_box(node, s);
            float t_near = 0.0f, t_far = h.t;
            for (int k = 0; k < 3; ++k) {
                const float near = inv_d[k] < 0 ? b.hi[k] : b.lo[k];
                const float far = inv_d[k] < 0 ? b.lo[k] : b.hi[k];
                t_near = std::max(t_near, (near - ray.o[k]) * inv_d[k]);
                t_far = std::min(t_far, (far - ray.o[k]) * inv_d[k]);
            }
            if (t_near > t_far * (1 + 2 * gamma3)) continue;
            if (node.count[s] == 0) {
                stack.push_back(node.child[s]);
                continue;
            }
            for (uint32_t j = 0; j < node.count[s]; ++j) {
                const gpu::TrianglePacket& p = bvh.packets[node.child[s] + j / MCRT_PACKET_WIDTH];
                const int i = int(j % MCRT_PACKET_WIDTH);
                glm::vec3 v[3];
                for (int k = 0; k < 3; ++k)
                    v[k] = {lane(p.v[3 * k], i), lane(p.v[3 * k + 1], i), lane(p.v[3 * k + 2], i)};
                float t = intersect(ray, v[0], v[1], v[2], h.t);
                if (t > 0.0f) h = {t, int64_t(p.index[i])};
            }
        }
        // Unordered, so bounded by 4 per level rather than the kernels' 3.
        if (stack.size() > size_t(4 * kMaxBvh4Depth)) {
            overflow = true;
            return h;
        }
    }
    return h;
}

// Random rays from around the scene, half of them aimed at a point inside its bounds.
void check_rays(const Scene& scene, const Bvh& bvh, int rays, uint32_t seed) {
    Box b;
    for (const glm::vec3& p : scene.positions) b.grow(p);
    if (scene.positions.empty()) b.lo = glm::vec3(0), b.hi = glm::vec3(1);
    const glm::vec3 diag = b.hi - b.lo, pad = glm::vec3(0.5f * glm::length(diag) + 0.1f);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto point_in = [&](glm::vec3 lo, glm::vec3 hi) {
        return lo + glm::vec3(u(rng), u(rng), u(rng)) * (hi - lo);
    };
    int hits = 0, mismatches = 0;
    bool overflow = false;
    for (int r = 0; r < rays; ++r) {
        Ray ray;
        ray.o = point_in(b.lo - pad, b.hi + pad);
        glm::vec3 target = r % 2 ? point_in(b.lo, b.hi) : point_in(b.lo - pad, b.hi + pad);
        ray.d = target - ray.o;
        if (glm::length(ray.d) == 0.0f) ray.d = glm::vec3(0.3f, 0.5f, 0.8f);
        ray.d = glm::normalize(ray.d);
        Hit want = brute_force(scene, ray), got = traverse(bvh, ray, overflow),
            got4 = traverse4(bvh, ray, overflow);
        hits += want.triangle >= 0;
        // Same closest t; a different triangle only when it ties at exactly that t.
        if (want.triangle != got.triangle && want.t != got.t) {
            if (mismatches++ == 0)
                UNSCOPED_INFO("ray " << r << ": brute force t " << want.t << " triangle "
                                     << want.triangle << ", BVH t " << got.t << " triangle "
                                     << got.triangle);
        }
        if (want.triangle != got4.triangle && want.t != got4.t) {
            if (mismatches++ == 0)
                UNSCOPED_INFO("ray " << r << ": brute force t " << want.t << " triangle "
                                     << want.triangle << ", BVH4 t " << got4.t << " triangle "
                                     << got4.triangle);
        }
    }
    CHECK(mismatches == 0);
    CHECK(!overflow);
    INFO("hits " << hits << " of " << rays);
    if (scene.triangle_count() > 0 && scene.triangle_count() != 1) CHECK(hits > rays / 20);
}

}  // namespace

TEST_CASE("BVH of a uniform random soup is valid, cheap and traced exactly", "[bvh]") {
    const BvhBuildOptions options;
    const Scene scene = random_soup(20000, 0.01f, 1);
    const Bvh bvh = build_bvh(scene, options);
    validate(scene, bvh, options);
    std::cout << "random soup, 20000 triangles: SAH cost " << bvh.stats.sah_cost << ", depth "
              << bvh.stats.depth << ", " << bvh.stats.inner_nodes << " inner nodes, "
              << bvh.stats.leaves << " leaves\n";
    // A single leaf costs N = 20000; a sound SAH tree over small triangles costs a few dozen.
    CHECK(bvh.stats.sah_cost > 10.0);
    CHECK(bvh.stats.sah_cost < 100.0);
    check_rays(scene, bvh, 10000, 2);
}

TEST_CASE("BVH cost does not depend on where the scene is (empty boxes are not points)", "[bvh]") {
    const BvhBuildOptions options;
    const Scene near = random_soup(5000, 0.01f, 3);
    const Scene far = random_soup(5000, 0.01f, 3, glm::vec3(300.0f, -500.0f, 200.0f));
    const Bvh a = build_bvh(near, options), b = build_bvh(far, options);
    validate(far, b, options);
    CHECK(b.stats.sah_cost == Approx(a.stats.sah_cost).epsilon(0.05));
}

TEST_CASE("BVH build options: bins and leaf sizes", "[bvh]") {
    const Scene scene = random_soup(3000, 0.02f, 4);
    for (int bins : {2, 8, 32})
        for (int max_leaf : {1, 4, 16}) {
            BvhBuildOptions options;
            options.bins = bins;
            options.max_leaf_size = max_leaf;
            options.traversal_cost = max_leaf == 4 ? 0.5f : 1.0f;
            INFO("bins " << bins << ", max_leaf_size " << max_leaf);
            const Bvh bvh = build_bvh(scene, options);
            validate(scene, bvh, options);
            CHECK(bvh.stats.sah_cost < 0.05 * scene.triangle_count());
            check_rays(scene, bvh, 1000, uint32_t(bins * 100 + max_leaf));
        }
}

TEST_CASE("BVH of a flat grid", "[bvh]") {
    const BvhBuildOptions options;
    const Scene scene = grid(60, 40);
    const Bvh bvh = build_bvh(scene, options);
    validate(scene, bvh, options);
    check_rays(scene, bvh, 10000, 5);
}

TEST_CASE("BVH of coincident triangles splits by index, never above max_leaf_size", "[bvh]") {
    for (size_t n : {size_t(8), size_t(9), size_t(1000)}) {
        const BvhBuildOptions options;
        const Scene scene = coincident(n);
        const Bvh bvh = build_bvh(scene, options);
        INFO(n << " coincident triangles");
        validate(scene, bvh, options);
        if (n <= size_t(options.max_leaf_size)) CHECK(bvh.nodes.size() == 1);
        check_rays(scene, bvh, 2000, 6);
    }
}

TEST_CASE("BVH of a single triangle is one leaf", "[bvh]") {
    const BvhBuildOptions options;
    const Scene scene = make_scene({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    const Bvh bvh = build_bvh(scene, options);
    validate(scene, bvh, options);
    REQUIRE(bvh.nodes.size() == 1);
    CHECK(node_count(bvh.nodes[0]) == 1);
    CHECK(bvh.stats.depth == 1);
    CHECK(bvh.stats.sah_cost == Approx(1.0));
    // The 4-wide root holds the leaf in slot 0 and three empty slots.
    REQUIRE(bvh.nodes4.size() == 1);
    CHECK(bvh.nodes4[0].count[0] == 1);
    CHECK(bvh.nodes4[0].child[0] == 0);
    for (int s = 1; s < 4; ++s) CHECK(is_empty_slot(bvh.nodes4[0], s));
    CHECK(bvh.stats.depth4 == 1);
    check_rays(scene, bvh, 10000, 7);
}

TEST_CASE("BVH of an empty scene is one empty leaf with a finite inverted box", "[bvh]") {
    const BvhBuildOptions options;
    const Scene scene;
    const Bvh bvh = build_bvh(scene, options);
    validate(scene, bvh, options);
    REQUIRE(bvh.nodes.size() == 1);
    const gpu::BvhNode& root = bvh.nodes[0];
    CHECK(node_count(root) == 0);
    CHECK(node_first(root) == 0);
    CHECK(root.lo.x > root.hi.x);
    CHECK(root.lo.y > root.hi.y);
    CHECK(root.lo.z > root.hi.z);
    CHECK(bvh.stats.sah_cost == 0.0);
    CHECK(bvh.stats.leaves == 1);
    CHECK(bvh.stats.inner_nodes == 0);
    check_rays(scene, bvh, 1000, 8);
}

TEST_CASE("BVH keeps degenerate triangles", "[bvh]") {
    const BvhBuildOptions options;
    const Scene scene = with_degenerates(4000, 9);
    const Bvh bvh = build_bvh(scene, options);
    validate(scene, bvh, options);
    check_rays(scene, bvh, 10000, 10);

    // Only points: no area anywhere, yet every leaf stays within max_leaf_size.
    std::vector<glm::vec3> points;
    for (int i = 0; i < 300; ++i)
        points.insert(points.end(), 3, glm::vec3(float(i % 7), 0.0f, 0.0f));
    const Scene collinear = make_scene(points);
    const Bvh line = build_bvh(collinear, options);
    validate(collinear, line, options);
}

TEST_CASE("BVH depth stays within kMaxBvhDepth on a pathological scene", "[bvh]") {
    const Scene scene = log_uniform_scatter(10000, 14);
    for (int max_leaf : {1, 8}) {
        BvhBuildOptions options;
        options.max_leaf_size = max_leaf;
        const Bvh bvh = build_bvh(scene, options);
        INFO("max_leaf_size " << max_leaf);
        validate(scene, bvh, options);
        std::cout << "log-uniform scatter, 10000 triangles, max_leaf_size " << max_leaf
                  << ": depth " << bvh.stats.depth << " (limit " << kMaxBvhDepth << "), 4-wide "
                  << bvh.stats.depth4 << " (limit " << kMaxBvh4Depth << ")\n";
        CHECK(bvh.stats.depth <= kMaxBvhDepth);
        CHECK(bvh.stats.depth4 <= kMaxBvh4Depth);
    }
}

TEST_CASE("BVH of a scene large enough for a multithreaded build is traced exactly", "[bvh]") {
    const BvhBuildOptions options;
    const Scene scene = random_soup(150000, 0.004f, 15);
    const Bvh bvh = build_bvh(scene, options);
    validate(scene, bvh, options);
    check_rays(scene, bvh, 500, 16);
    const Bvh again = build_bvh(scene, options);
    REQUIRE(again.nodes.size() == bvh.nodes.size());
    CHECK(std::memcmp(again.nodes.data(), bvh.nodes.data(),
                      bvh.nodes.size() * sizeof(gpu::BvhNode)) == 0);
    REQUIRE(again.nodes4.size() == bvh.nodes4.size());
    CHECK(std::memcmp(again.nodes4.data(), bvh.nodes4.data(),
                      bvh.nodes4.size() * sizeof(gpu::Bvh4Node)) == 0);
}

TEST_CASE("BVH build is deterministic", "[bvh]") {
    const Scene scene = with_degenerates(5000, 11);
    const Bvh a = build_bvh(scene), b = build_bvh(scene);
    REQUIRE(a.nodes.size() == b.nodes.size());
    CHECK(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(gpu::BvhNode)) == 0);
    CHECK(std::memcmp(a.triangles.data(), b.triangles.data(),
                      a.triangles.size() * sizeof(gpu::Triangle)) == 0);
}

TEST_CASE("BVH build rejects invalid options", "[bvh]") {
    const Scene scene = random_soup(10, 0.1f, 12);
    BvhBuildOptions options;
    options.bins = 1;
    CHECK_THROWS_AS(build_bvh(scene, options), InputError);
    options = {};
    options.max_leaf_size = 0;
    CHECK_THROWS_AS(build_bvh(scene, options), InputError);
    Scene broken = scene;
    broken.positions.pop_back();
    CHECK_THROWS_AS(build_bvh(broken, {}), InputError);
}

// Completes on a million triangles; the rate is printed, never asserted (benchmarks time things).
TEST_CASE("BVH build of a million triangles completes", "[bvh][large]") {
    const BvhBuildOptions options;
    const Scene scene = noisy_sphere_and_soup(500, 500, 500000, 13);
    REQUIRE(scene.triangle_count() == 1000000);
    const Bvh bvh = build_bvh(scene, options);
    std::cout << "1M synthetic triangles (noisy sphere + soup): build " << bvh.stats.build_seconds
              << " s, " << scene.triangle_count() / bvh.stats.build_seconds / 1e6
              << " M triangles/s, SAH cost " << bvh.stats.sah_cost << ", depth " << bvh.stats.depth
              << ", " << bvh.nodes.size() << " nodes; 4-wide: collapse "
              << bvh.stats.collapse_seconds << " s, SAH cost " << bvh.stats.sah_cost4 << ", depth "
              << bvh.stats.depth4 << ", " << bvh.nodes4.size() << " nodes, "
              << bvh.stats.bytes / 1048576.0 << " MiB on the device\n";
    validate(scene, bvh, options);
}
