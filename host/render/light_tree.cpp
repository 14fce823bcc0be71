#include "render/light_tree.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>

namespace mcrt {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kBuckets = 12;  // per axis, as pbrt-v4's BVHLightSampler

double safe_acos(double x) { return std::acos(std::clamp(x, -1.0, 1.0)); }

// A cone of directions, unit axis w and cos of its half-angle θ (pbrt-v4's DirectionCone).
struct Cone {
    glm::dvec3 w{0.0, 0.0, 1.0};
    double cos_theta = 1.0;
    bool empty = true;
};

Cone whole_sphere(const glm::dvec3& w) { return Cone{w, -1.0, false}; }

// Smallest cone about an axis in the plane of both axes holding both cones (Conty Estevez &
// Kulla 2018, Algorithm 1).
Cone cone_union(const Cone& a, const Cone& b) {
    if (a.empty) return b;
    if (b.empty) return a;
    // Without trigonometry the common cases of the build: a holds everything, or holds b's
    // single direction (a light's normal).
    if (a.cos_theta <= -1.0) return a;
    if (b.cos_theta >= 1.0 && glm::dot(a.w, b.w) >= a.cos_theta) return a;
    double theta_a = safe_acos(a.cos_theta), theta_b = safe_acos(b.cos_theta);
    double theta_d = safe_acos(glm::dot(a.w, b.w));
    if (std::min(theta_d + theta_b, kPi) <= theta_a) return a;
    if (std::min(theta_d + theta_a, kPi) <= theta_b) return b;
    double theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if (theta_o >= kPi) return whole_sphere(a.w);
    glm::dvec3 axis = glm::cross(a.w, b.w);
    double length = glm::length(axis);
    if (!(length > 0.0)) return whole_sphere(a.w);
    axis /= length;
    // a.w turned by θ_o − θ_a toward b.w (Rodrigues, axis ⟂ a.w): the new cone's axis.
    double theta_r = theta_o - theta_a;
    glm::dvec3 w = a.w * std::cos(theta_r) + glm::cross(axis, a.w) * std::sin(theta_r);
    return Cone{glm::normalize(w), std::cos(theta_o), false};
}

// What a node bounds: box, power, normals, emission spread (pbrt-v4's LightBounds).
struct Bounds {
    glm::dvec3 lo{std::numeric_limits<double>::infinity()};
    glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
    double phi = 0.0;
    Cone normals;
    double cos_e = 1.0;  // cos θ_e: the least over the lights
    bool two_sided = false;

    void add(const Bounds& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
        phi += b.phi;
        normals = cone_union(normals, b.normals);
        cos_e = std::min(cos_e, b.cos_e);
        two_sided = two_sided || b.two_sided;
    }
    double surface_area() const {
        glm::dvec3 d = hi - lo;
        return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    }
};

// Orientation measure M_Ω of a cone of normals θ_o spreading light θ_e beyond it: the cosine-
// weighted solid angle it can emit into (Conty Estevez & Kulla 2018, eq. 1).
double orientation_measure(double cos_o, double cos_e) {
    double theta_o = safe_acos(cos_o), theta_e = safe_acos(cos_e);
    double theta_w = std::min(theta_o + theta_e, kPi);
    double sin_o = std::sqrt(std::max(0.0, 1.0 - cos_o * cos_o));
    return 2.0 * kPi * (1.0 - cos_o) +
           0.5 * kPi *
               (2.0 * theta_w * sin_o - std::cos(theta_o - 2.0 * theta_w) - 2.0 * theta_o * sin_o +
                cos_o);
}

// Surface-area-orientation cost of a child, kr the parent's aspect penalty for the split axis
// (pbrt-v4's EvaluateCost).
double saoh_cost(const Bounds& b, double kr) {
    return b.phi * orientation_measure(b.normals.cos_theta, b.cos_e) * kr * b.surface_area();
}

float round_down(double x) {
    float f = float(x);
    return double(f) > x ? std::nextafter(f, -2.0f) : f;
}

float round_up(double x) {
    float f = float(x);
    return double(f) < x ? std::nextafter(f, 2.0f * f + 1.0f) : f;
}

int ceil_log2(size_t n) {
    int k = 0;
    while ((size_t(1) << k) < n) ++k;
    return k;
}

struct Builder {
    const std::vector<Bounds>& items;
    std::vector<glm::dvec3> centroid;
    std::vector<uint32_t> order;  // items of the tree, permuted in place by the splits
    LightTree& out;

    gpu::LightTreeNode node_of(const Bounds& b) const {
        gpu::LightTreeNode n{};
        n.lo = {float(b.lo.x), float(b.lo.y), float(b.lo.z), float(b.phi)};
        // Widened by 1e-6 rad and rounded down, so that the float cone still holds every normal.
        double cos_o = b.normals.cos_theta <= -1.0
                           ? -1.0
                           : std::cos(std::min(kPi, safe_acos(b.normals.cos_theta) + 1e-6));
        n.hi = {float(b.hi.x), float(b.hi.y), float(b.hi.z), round_down(cos_o)};
        n.axis = {float(b.normals.w.x), float(b.normals.w.y), float(b.normals.w.z),
                  round_down(b.cos_e)};
        n.flags = b.two_sided ? LIGHT_NODE_TWO_SIDED : 0u;
        n.radius = round_up(
            0.5 * glm::length(glm::dvec3(n.hi.x - n.lo.x, n.hi.y - n.lo.y, n.hi.z - n.lo.z)));
        n.sin_o = std::min(
            1.0f, round_up(std::sqrt(std::max(0.0, 1.0 - double(n.hi.w) * double(n.hi.w)))));
        return n;
    }

    // Node `index` over order[begin, end), reached by `trail` at `depth`.
    void build(size_t begin, size_t end, uint32_t index, uint32_t trail, int depth) {
        Bounds all, centroids;
        for (size_t i = begin; i < end; ++i) {
            all.add(items[order[i]]);
            centroids.lo = glm::min(centroids.lo, centroid[order[i]]);
            centroids.hi = glm::max(centroids.hi, centroid[order[i]]);
        }
        out.nodes[index] = node_of(all);
        if (end - begin == 1) {
            const uint32_t light = order[begin];
            out.nodes[index].child = light;
            out.nodes[index].flags |= LIGHT_NODE_LEAF;
            out.paths[light] = {trail, uint32_t(depth) + 1u};
            return;
        }
        size_t mid = split(begin, end, all, centroids, depth);
        const uint32_t first = uint32_t(out.nodes.size());
        out.nodes[index].child = first;
        out.nodes.resize(out.nodes.size() + 2);
        build(begin, mid, first, trail, depth + 1);
        build(mid, end, first + 1, trail | (1u << depth), depth + 1);
    }

    // Where order[begin, end) is cut: the binned SAOH's best bucket boundary, or the median of
    // the widest centroid axis when no bucket split exists or the path would grow too long.
    size_t split(size_t begin, size_t end, const Bounds& all, const Bounds& centroids, int depth) {
        const size_t n = end - begin;
        if (n == 2) return begin + 1;  // the one split there is
        const bool balance = depth + ceil_log2(n) >= MCRT_LIGHT_TREE_MAX_DEPTH;
        const glm::dvec3 diagonal = all.hi - all.lo, extent = centroids.hi - centroids.lo;
        double best_cost = std::numeric_limits<double>::infinity();
        int best_dim = -1, best_bucket = -1;
        auto bucket_of = [&](uint32_t item, int dim) {
            double t = (centroid[item][dim] - centroids.lo[dim]) / extent[dim];
            return std::clamp(int(t * kBuckets), 0, kBuckets - 1);
        };
        for (int dim = 0; dim < 3 && !balance; ++dim) {
            if (!(extent[dim] > 0.0)) continue;
            Bounds bucket[kBuckets];
            size_t count[kBuckets] = {};
            for (size_t i = begin; i < end; ++i) {
                int b = bucket_of(order[i], dim);
                bucket[b].add(items[order[i]]);
                ++count[b];
            }
            double max_extent = std::max({diagonal.x, diagonal.y, diagonal.z});
            double kr = diagonal[dim] > 0.0 ? max_extent / diagonal[dim] : 1.0;
            Bounds above[kBuckets];  // above[s]: buckets s .. end
            size_t count_above[kBuckets + 1] = {};
            for (int s = kBuckets - 1; s >= 0; --s) {
                above[s] = bucket[s];
                if (s + 1 < kBuckets) above[s].add(above[s + 1]);
                count_above[s] = count_above[s + 1] + count[s];
            }
            Bounds below;
            size_t count_below = 0;
            for (int s = 0; s + 1 < kBuckets; ++s) {
                below.add(bucket[s]);
                count_below += count[s];
                if (count_below == 0 || count_above[s + 1] == 0) continue;
                double cost = saoh_cost(below, kr) + saoh_cost(above[s + 1], kr);
                if (cost < best_cost) {
                    best_cost = cost;
                    best_dim = dim;
                    best_bucket = s;
                }
            }
        }
        if (best_dim >= 0) {
            auto it = std::partition(
                order.begin() + long(begin), order.begin() + long(end),
                [&](uint32_t item) { return bucket_of(item, best_dim) <= best_bucket; });
            size_t mid = size_t(it - order.begin());
            if (mid > begin && mid < end) return mid;
        }
        int dim = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
        size_t mid = begin + n / 2;
        std::nth_element(
            order.begin() + long(begin), order.begin() + long(mid), order.begin() + long(end),
            [&](uint32_t a, uint32_t b) { return centroid[a][dim] < centroid[b][dim]; });
        return mid;
    }
};

}  // namespace

LightTree build_light_tree(const std::vector<gpu::Light>& lights,
                           const std::vector<double>& powers) {
    LightTree tree;
    tree.paths.assign(lights.size(), gpu::LightTreePath{0u, 0u});
    std::vector<Bounds> items(lights.size());
    std::vector<glm::dvec3> centroid(lights.size());
    std::vector<uint32_t> order;
    for (size_t i = 0; i < lights.size(); ++i) {
        const gpu::Light& l = lights[i];
        glm::dvec3 p[3] = {
            {l.p0.x, l.p0.y, l.p0.z}, {l.p1.x, l.p1.y, l.p1.z}, {l.p2.x, l.p2.y, l.p2.z}};
        glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
        double length = glm::length(normal);
        if (!(powers[i] > 0.0)) continue;
        Bounds& b = items[i];
        b.lo = glm::min(p[0], glm::min(p[1], p[2]));
        b.hi = glm::max(p[0], glm::max(p[1], p[2]));
        b.phi = powers[i];
        // An area light: its normal, emitting over the hemisphere (θ_o = 0, θ_e = π/2), on
        // both sides when double-sided (pbrt-v4's DiffuseAreaLight::Bounds).
        // A sliver whose normal is lost to rounding may emit anywhere: the whole sphere.
        b.normals = length > 0.0 ? Cone{normal / length, 1.0, false} : whole_sphere({0, 0, 1});
        b.cos_e = 0.0;
        b.two_sided = (l.flags & MATERIAL_DOUBLE_SIDED) != 0u;
        centroid[i] = 0.5 * (b.lo + b.hi);
        order.push_back(uint32_t(i));
    }
    if (order.empty()) return tree;
    tree.nodes.reserve(2 * order.size() - 1);
    tree.nodes.resize(1);
    Builder builder{items, std::move(centroid), std::move(order), tree};
    builder.build(0, builder.order.size(), 0u, 0u, 0);
    return tree;
}

std::vector<uint32_t> light_tree_words(const LightTree& tree) {
    const size_t nodes = std::max<size_t>(tree.nodes.size(), 1);  // an empty tree: one zero node
    std::vector<uint32_t> words((nodes * sizeof(gpu::LightTreeNode) +
                                 tree.paths.size() * sizeof(gpu::LightTreePath)) /
                                    sizeof(uint32_t),
                                0u);
    if (!tree.nodes.empty())
        std::memcpy(words.data(), tree.nodes.data(), tree.nodes.size() * sizeof(gpu::LightTreeNode));
    if (!tree.paths.empty())
        std::memcpy(words.data() + nodes * sizeof(gpu::LightTreeNode) / sizeof(uint32_t),
                    tree.paths.data(), tree.paths.size() * sizeof(gpu::LightTreePath));
    return words;
}

}  // namespace mcrt
