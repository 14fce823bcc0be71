// MikkTSpace tangents (Mikkelsen 2008, "Simulation of wrinkled surfaces revisited"), written
// after the method of the reference mikktspace.c: weld, per-triangle frames, neighbours, groups
// around each vertex, the angle-weighted mean per group, degenerate triangles last. Its subgroup
// split is left out: at the default angular threshold of 180° it never splits a group.
#include "scene/tangents.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <tuple>
#include <unordered_map>

namespace mcrt {

namespace {

// MikkTSpace's test for zero: below the smallest normal float.
bool not_zero(double x) { return std::abs(x) > std::numeric_limits<float>::min(); }
bool not_zero(const glm::dvec3& v) { return not_zero(v.x) || not_zero(v.y) || not_zero(v.z); }

glm::dvec3 normalize_if_not_zero(const glm::dvec3& v) {
    return not_zero(v) ? glm::normalize(v) : v;
}

// `v` projected onto the plane orthogonal to unit `n`, normalized (kept when zero).
glm::dvec3 project_onto_plane(const glm::dvec3& v, const glm::dvec3& n) {
    return normalize_if_not_zero(v - glm::dot(n, v) * n);
}

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

// The vertex of each corner: corners with bit-identical position, normal and texture coordinates
// share one (MikkTSpace welds on exact equality).
std::vector<uint32_t> weld(const std::vector<glm::dvec3>& positions,
                           const std::vector<glm::dvec3>& normals,
                           const std::vector<glm::dvec2>& texcoords) {
    using Key = std::array<double, 8>;
    struct KeyHash {
        size_t operator()(const Key& key) const {
            size_t h = 0;
            for (double d : key) {
                uint64_t bits;
                std::memcpy(&bits, &d, sizeof bits);
                h = (h ^ std::hash<uint64_t>()(bits)) * 1099511628211u;
            }
            return h;
        }
    };
    std::unordered_map<Key, uint32_t, KeyHash> ids;
    ids.reserve(positions.size());
    std::vector<uint32_t> vertex(positions.size());
    for (size_t c = 0; c < positions.size(); ++c) {
        const Key key{positions[c].x, positions[c].y, positions[c].z, normals[c].x,
                      normals[c].y,   normals[c].z,   texcoords[c].x, texcoords[c].y};
        vertex[c] = ids.emplace(key, static_cast<uint32_t>(ids.size())).first->second;
    }
    return vertex;
}

// What one triangle contributes (mikktspace.c InitTriInfo).
struct TriangleFrame {
    glm::dvec3 s{0.0};                    // unit dP/du, zero where it is undefined
    bool orientation_preserving = false;  // signed area in texture space > 0
    bool group_with_any = true;           // the texture map spans no area: adds nothing
    bool degenerate = false;              // two corners at one position: not in any group
    std::array<uint32_t, 3> neighbour{kNone, kNone, kNone};  // across edge corner k → k+1
    std::array<uint32_t, 3> group{kNone, kNone, kNone};      // of corner k
};

// dP/du and dP/dv from the edges and texture-space edges (the paper's first-order derivatives).
void init_frame(TriangleFrame& frame, const glm::dvec3* p, const glm::dvec2* uv) {
    const glm::dvec3 d1 = p[1] - p[0], d2 = p[2] - p[0];
    const glm::dvec2 t21 = uv[1] - uv[0], t31 = uv[2] - uv[0];
    const double signed_area = t21.x * t31.y - t21.y * t31.x;  // twice the texture-space area
    frame.orientation_preserving = signed_area > 0.0;
    if (!not_zero(signed_area)) return;
    // Area × dP/du and area × dP/dv.
    const glm::dvec3 s = t31.y * d1 - t21.y * d2;
    const glm::dvec3 t = -t31.x * d1 + t21.x * d2;
    const double sign = frame.orientation_preserving ? 1.0 : -1.0;
    const double length_s = glm::length(s), length_t = glm::length(t);
    if (not_zero(length_s)) frame.s = (sign / length_s) * s;
    frame.group_with_any =
        !(not_zero(length_s / std::abs(signed_area)) && not_zero(length_t / std::abs(signed_area)));
}

// Pairs each edge with an edge of another triangle that runs the other way between the same two
// vertices, first come first paired (mikktspace.c BuildNeighborsFast).
void find_neighbours(std::vector<TriangleFrame>& frames, const std::vector<uint32_t>& vertex) {
    struct Edge {
        uint32_t low, high, triangle;
        uint8_t k;  // edge corner k → k+1
    };
    std::vector<Edge> edges;
    edges.reserve(3 * frames.size());
    for (uint32_t f = 0; f < frames.size(); ++f) {
        if (frames[f].degenerate) continue;
        for (uint8_t k = 0; k < 3; ++k) {
            const uint32_t i0 = vertex[3 * f + k], i1 = vertex[3 * f + (k + 1) % 3];
            edges.push_back(Edge{std::min(i0, i1), std::max(i0, i1), f, k});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
        return std::tie(a.low, a.high, a.triangle, a.k) < std::tie(b.low, b.high, b.triangle, b.k);
    });
    auto from = [&](const Edge& e) { return vertex[3 * e.triangle + e.k]; };
    for (size_t i = 0; i < edges.size(); ++i) {
        const Edge& a = edges[i];
        if (frames[a.triangle].neighbour[a.k] != kNone) continue;
        for (size_t j = i + 1; j < edges.size() && edges[j].low == a.low && edges[j].high == a.high;
             ++j) {
            const Edge& b = edges[j];
            if (from(b) != from(a) && frames[b.triangle].neighbour[b.k] == kNone) {
                frames[a.triangle].neighbour[a.k] = b.triangle;
                frames[b.triangle].neighbour[b.k] = a.triangle;
                break;
            }
        }
    }
}

// The corner of `triangle` at vertex `v` (its corners are distinct vertices: it is not degenerate).
int corner_at(const std::vector<uint32_t>& vertex, uint32_t triangle, uint32_t v) {
    for (int k = 0; k < 3; ++k) {
        if (vertex[3 * triangle + static_cast<size_t>(k)] == v) return k;
    }
    return -1;
}

struct Group {
    uint32_t vertex;
    bool orientation_preserving;
};

// Groups triangles around each vertex: from a triangle corner not yet grouped, across the two
// edges at that vertex to neighbours of the same orientation; a triangle that spans no texture
// area takes the orientation of the first group that reaches it (mikktspace.c Build4RuleGroups
// and AssignRecur, with a stack for the recursion).
std::vector<Group> build_groups(std::vector<TriangleFrame>& frames,
                                const std::vector<uint32_t>& vertex) {
    std::vector<Group> groups;
    std::vector<uint32_t> stack;
    for (uint32_t f = 0; f < frames.size(); ++f) {
        for (int k = 0; k < 3; ++k) {
            if (frames[f].degenerate || frames[f].group_with_any || frames[f].group[k] != kNone) {
                continue;
            }
            const uint32_t g = static_cast<uint32_t>(groups.size());
            const Group group{vertex[3 * f + static_cast<size_t>(k)],
                              frames[f].orientation_preserving};
            groups.push_back(group);
            frames[f].group[k] = g;
            stack = {frames[f].neighbour[(k + 2) % 3], frames[f].neighbour[k]};
            while (!stack.empty()) {
                const uint32_t m = stack.back();
                stack.pop_back();
                if (m == kNone) continue;
                TriangleFrame& frame = frames[m];
                const int j = corner_at(vertex, m, group.vertex);
                if (j < 0 || frame.group[j] != kNone) continue;
                if (frame.group_with_any && frame.group[0] == kNone && frame.group[1] == kNone &&
                    frame.group[2] == kNone) {
                    frame.orientation_preserving = group.orientation_preserving;
                }
                if (frame.orientation_preserving != group.orientation_preserving) continue;
                frame.group[j] = g;
                stack.push_back(frame.neighbour[(j + 2) % 3]);
                stack.push_back(frame.neighbour[j]);
            }
        }
    }
    return groups;
}

}  // namespace

glm::dvec3 any_tangent(const glm::dvec3& n) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    return glm::dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

std::vector<glm::dvec4> generate_tangents(const std::vector<glm::dvec3>& positions,
                                          const std::vector<glm::dvec3>& normals,
                                          const std::vector<glm::dvec2>& gltf_texcoords) {
    // MikkTSpace's frame is for v up the image, glTF's v runs down: v is negated, which keeps
    // dP/du and flips the orientation, so that w = +1 where the map is not mirrored.
    std::vector<glm::dvec2> texcoords(gltf_texcoords.size());
    for (size_t c = 0; c < texcoords.size(); ++c) {
        texcoords[c] = glm::dvec2(gltf_texcoords[c].x, -gltf_texcoords[c].y);
    }
    const std::vector<uint32_t> vertex = weld(positions, normals, texcoords);
    const size_t triangles = positions.size() / 3;

    // Step 1: each triangle's frame; those with two corners at one position take no part.
    std::vector<TriangleFrame> frames(triangles);
    for (size_t f = 0; f < triangles; ++f) {
        const glm::dvec3* p = &positions[3 * f];
        frames[f].degenerate = p[0] == p[1] || p[0] == p[2] || p[1] == p[2];
        if (!frames[f].degenerate) init_frame(frames[f], p, &texcoords[3 * f]);
    }
    find_neighbours(frames, vertex);
    const std::vector<Group> groups = build_groups(frames, vertex);

    // Step 2: per group, the mean of its triangles' dP/du in the vertex's tangent plane, each
    // weighted by the triangle's angle at the vertex in that plane (mikktspace.c EvalTspace).
    std::vector<glm::dvec3> sum(groups.size(), glm::dvec3(0.0));
    for (size_t f = 0; f < triangles; ++f) {
        if (frames[f].degenerate || frames[f].group_with_any) continue;
        for (size_t k = 0; k < 3; ++k) {
            const uint32_t g = frames[f].group[k];
            if (g == kNone) continue;
            const glm::dvec3& n = normals[3 * f + k];
            const glm::dvec3& p = positions[3 * f + k];
            const glm::dvec3 to_previous =
                project_onto_plane(positions[3 * f + (k + 2) % 3] - p, n);
            const glm::dvec3 to_next = project_onto_plane(positions[3 * f + (k + 1) % 3] - p, n);
            const double angle = std::acos(std::clamp(glm::dot(to_previous, to_next), -1.0, 1.0));
            sum[g] += angle * project_onto_plane(frames[f].s, n);
        }
    }

    // Step 3: each grouped corner takes its group's frame; the others any frame of their normal.
    std::vector<glm::dvec4> tangents(positions.size());
    std::vector<uint32_t> first_grouped(positions.size(), kNone);  // by vertex: a grouped corner
    for (size_t c = 0; c < positions.size(); ++c) {
        const uint32_t g = frames[c / 3].group[c % 3];
        if (g == kNone || !not_zero(sum[g])) {
            tangents[c] = glm::dvec4(any_tangent(normals[c]), 1.0);
        } else {
            tangents[c] =
                glm::dvec4(glm::normalize(sum[g]), groups[g].orientation_preserving ? 1.0 : -1.0);
        }
        if (g != kNone && first_grouped[vertex[c]] == kNone) {
            first_grouped[vertex[c]] = static_cast<uint32_t>(c);
        }
    }
    // Step 4: a degenerate triangle's corner copies a grouped corner of its vertex
    // (mikktspace.c DegenEpilogue).
    for (size_t c = 0; c < positions.size(); ++c) {
        if (frames[c / 3].degenerate && first_grouped[vertex[c]] != kNone) {
            tangents[c] = tangents[first_grouped[vertex[c]]];
        }
    }
    return tangents;
}

}  // namespace mcrt
