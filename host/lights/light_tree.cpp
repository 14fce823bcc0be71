#include "lights/light_tree.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>
#include <type_traits>

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

// cos and sin of half an angle θ ∈ [0, π] given cos θ: both ≥ 0.
struct Half {
    double c, s;
};
Half half_angle(double cos_theta) {
    return {std::sqrt(std::max(0.0, 0.5 * (1.0 + cos_theta))),
            std::sqrt(std::max(0.0, 0.5 * (1.0 - cos_theta)))};
}

// Smallest cone about an axis in the plane of both axes holding both cones (Conty Estevez &
// Kulla 2018, Algorithm 1), its angles held as cosines and sines of half-angles, which lie in
// [0, π/2] and sum to at most 3π/2 without ambiguity: sums by the addition formulas, no
// trigonometry.
Cone cone_union(const Cone& a, const Cone& b) {
    if (a.empty) return b;
    if (b.empty) return a;
    if (a.cos_theta <= -1.0) return a;
    if (b.cos_theta <= -1.0) return b;
    const double cos_d = std::clamp(glm::dot(a.w, b.w), -1.0, 1.0);
    if (b.cos_theta >= 1.0) {  // the build's most common case: b a light's normal
        if (cos_d >= a.cos_theta) return a;
        // θ_o = (θ_a + θ_d) / 2 < π; the axis turned by (θ_d − θ_a) / 2 toward b.w, along
        // b.w's part normal to a.w, of length sin θ_d = 2 sin(θ_d/2) cos(θ_d/2).
        const Half ha = half_angle(a.cos_theta), hd = half_angle(cos_d);
        const double sin_d = 2.0 * hd.s * hd.c;
        if (!(sin_d > 0.0)) return whole_sphere(a.w);  // b.w opposite a.w
        const double cos_r = hd.c * ha.c + hd.s * ha.s, sin_r = hd.s * ha.c - hd.c * ha.s;
        glm::dvec3 w = a.w * cos_r + (b.w - cos_d * a.w) * (sin_r / sin_d);
        return Cone{glm::normalize(w), ha.c * hd.c - ha.s * hd.s, false};
    }
    const Half ha = half_angle(a.cos_theta), hb = half_angle(b.cos_theta), hd = half_angle(cos_d);
    // θ_d + θ_b ≤ θ_a: a holds b (the half-angles' sum lies in [0, π], where cos decreases).
    if (hd.c * hb.c - hd.s * hb.s >= ha.c) return a;
    if (hd.c * ha.c - hd.s * ha.s >= hb.c) return b;
    // θ_o = (θ_a + θ_d + θ_b) / 2, first θ_a/2 + θ_d/2 ∈ [0, π], then + θ_b/2.
    const Half ad{ha.c * hd.c - ha.s * hd.s, ha.s * hd.c + ha.c * hd.s};
    const double cos_o = ad.c * hb.c - ad.s * hb.s, sin_o = ad.s * hb.c + ad.c * hb.s;
    if (sin_o <= 0.0) return whole_sphere(a.w);  // θ_o ≥ π
    glm::dvec3 axis = glm::cross(a.w, b.w);
    double length = glm::length(axis);
    if (!(length > 0.0)) return whole_sphere(a.w);
    axis /= length;
    // a.w turned by θ_r = θ_o − θ_a toward b.w (Rodrigues, axis ⟂ a.w): the new cone's axis.
    const double cos_a = a.cos_theta, sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
    const double cos_r = cos_o * cos_a + sin_o * sin_a, sin_r = sin_o * cos_a - cos_o * sin_a;
    glm::dvec3 w = a.w * cos_r + glm::cross(axis, a.w) * sin_r;
    return Cone{glm::normalize(w), cos_o, false};
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
    // As add, with a looser cone that is cheap to take: about the first axis it was given,
    // widened to hold b's cone. What the bins estimate costs with; the tree's own bounds come
    // from add.
    void add_estimate(const Bounds& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
        phi += b.phi;
        cos_e = std::min(cos_e, b.cos_e);
        two_sided = two_sided || b.two_sided;
        if (b.normals.empty || normals.cos_theta <= -1.0) return;
        if (normals.empty || b.normals.cos_theta <= -1.0) {
            normals = b.normals;
            return;
        }
        const double cos_d = std::clamp(glm::dot(normals.w, b.normals.w), -1.0, 1.0);
        double cos_reach = cos_d;  // cos(θ_d + θ_b), −1 beyond π
        if (b.normals.cos_theta < 1.0) {
            const double sin_d = std::sqrt(std::max(0.0, 1.0 - cos_d * cos_d));
            const double cos_b = b.normals.cos_theta;
            const double sin_b = std::sqrt(std::max(0.0, 1.0 - cos_b * cos_b));
            cos_reach = sin_d * cos_b + cos_d * sin_b < 0.0 ? -1.0 : cos_d * cos_b - sin_d * sin_b;
        }
        normals.cos_theta = std::min(normals.cos_theta, cos_reach);
    }
    double surface_area() const {
        glm::dvec3 d = hi - lo;
        return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    }
};

// Orientation measure M_Ω of a cone of normals θ_o spreading light θ_e beyond it: the cosine-
// weighted solid angle it can emit into (Conty Estevez & Kulla 2018, eq. 1). For area lights
// (θ_e = π/2, every light here) eq. 1 is 2π − π cos θ_o + (π²/2) sin θ_o where θ_o ≤ π/2
// (θ_w = θ_o + π/2) and 2π (1 − cos θ_o) + π (π − θ_o) sin θ_o beyond (θ_w = π): the build's
// most frequent call with one acos at most.
double orientation_measure(double cos_o, double cos_e) {
    const double sin_o = std::sqrt(std::max(0.0, 1.0 - cos_o * cos_o));
    if (cos_e == 0.0) {
        if (cos_o >= 0.0) return 2.0 * kPi - kPi * cos_o + 0.5 * kPi * kPi * sin_o;
        // π − θ_o = acos(−cos θ_o) by Abramowitz & Stegun 4.4.46 (error ≤ 2e-8 rad): a cost,
        // not a bound, needs no more.
        const double x = std::min(1.0, -cos_o);
        const double acos_x =
            std::sqrt(1.0 - x) *
            (1.5707963050 +
             x * (-0.2145988016 +
                  x * (0.0889789874 +
                       x * (-0.0501743046 +
                            x * (0.0308918810 +
                                 x * (-0.0170881256 + x * (0.0066700901 - 0.0012624911 * x)))))));
        return 2.0 * kPi * (1.0 - cos_o) + kPi * acos_x * sin_o;
    }
    double theta_o = safe_acos(cos_o), theta_e = safe_acos(cos_e);
    double theta_w = std::min(theta_o + theta_e, kPi);
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

// Runs a on a thread of its own beside b on this one, or both here where the process may
// start no thread (a limit on processes): the same results either way.
template <typename A, typename B>
void beside(A&& a, B&& b) {
    std::thread thread;
    try {
        thread = std::thread(a);
    } catch (const std::system_error&) {
        a();
        b();
        return;
    }
    b();
    thread.join();
}

// fn(begin, end) over [0, n) in `threads` contiguous parts at once (those no thread could be
// started for run here).
template <typename Fn>
void parallel_for(int threads, size_t n, Fn fn) {
    std::vector<std::thread> workers;
    const size_t parts = n < 65536 ? 1 : size_t(std::max(1, threads));
    for (size_t t = 1; t < parts; ++t) {
        auto part = [=] { fn(n * t / parts, n * (t + 1) / parts); };
        try {
            workers.emplace_back(part);
        } catch (const std::system_error&) {
            part();
        }
    }
    fn(0, n / parts);
    for (std::thread& w : workers) w.join();
}

// The threads a build may still start beyond its own: taken before a thread starts, given back
// when its work is done, so that work still running elsewhere can take it.
class ThreadBudget {
  public:
    explicit ThreadBudget(int spare) : spare_(spare) {}
    bool take() {
        int n = spare_.load();
        while (n > 0)
            if (spare_.compare_exchange_weak(n, n - 1)) return true;
        return false;
    }
    void give_back() { spare_ += 1; }

  private:
    std::atomic<int> spare_;
};

// Longest path of the binary tree, in edges: collapsed two levels to a node, its lights lie at
// most MCRT_LIGHT_TREE_MAX_DEPTH nodes deep.
constexpr int kMaxBinaryDepth = 2 * MCRT_LIGHT_TREE_MAX_DEPTH;
// Subtrees of more lights than this are built on a thread of their own while threads are free.
constexpr size_t kParallelGrain = 4096;
// Splits of more than twice this many lights bin and partition in chunks of it, in parallel.
constexpr size_t kChunk = size_t(1) << 16;
// Splits of at most this many lights are found by a sweep, of more by the bins.
constexpr size_t kSweepMax = 16;

// A node of the binary tree the wide one is collapsed from.
struct BinaryNode {
    Bounds bounds;
    uint32_t left = 0;  // inner: index of the first child (the second follows its subtree)
    uint32_t right = 0;
    uint32_t light = 0;  // leaf: its light
    bool leaf = false;
    uint32_t wide_nodes = 0;  // the nodes of the four-wide tree this node would root
};

// Top-down binary build, depth first: the subtree over order[begin, end) of m lights takes the
// 2m − 1 nodes from its index on, so that subtrees are built apart (in parallel) into places
// fixed by the splits alone, and the tree is the same whatever the number of threads.
struct BinaryBuilder {
    const Bounds* items;
    const std::vector<glm::dvec3>& centroid;
    std::vector<uint32_t>& order;  // items of the tree, permuted in place by the splits
    BinaryNode* nodes;  // storage for 2 · lights − 1, each constructed as its subtree is built
    ThreadBudget& budget;

    // The bins of one axis each: bounds (estimated cones) and counts.
    struct Bins {
        Bounds bucket[3][kBuckets];
        size_t count[3][kBuckets] = {};
    };

    // What the parent's split found out about the lights of a child: their bounds and the box
    // of their centroids.
    struct Side {
        Bounds bounds;
        Bounds centroids;  // lo, hi only

        void add(const Bounds& item, const glm::dvec3& c) {
            bounds.add(item);
            centroids.lo = glm::min(centroids.lo, c);
            centroids.hi = glm::max(centroids.hi, c);
        }
    };

    // `given`: what is known of order[begin, end), nullptr at the root.
    void build(size_t begin, size_t end, uint32_t index, int depth, const Side* given) {
        // Constructed here, on the thread that builds it: the pages are first touched in
        // parallel.
        BinaryNode& node = *new (&nodes[index]) BinaryNode();
        Side all;
        if (given != nullptr) {
            all = *given;
        } else {
            // The root: in fixed chunks, half of them on a free thread, merged in chunk order.
            const size_t chunks = (end - begin + kChunk - 1) / kChunk;
            std::vector<Side> parts(chunks);
            auto take = [&](size_t from, size_t to) {
                for (size_t c = from; c < to; ++c)
                    for (size_t i = begin + c * kChunk; i < std::min(end, begin + (c + 1) * kChunk);
                         ++i)
                        parts[c].add(items[order[i]], centroid[order[i]]);
            };
            if (chunks > 1 && budget.take()) {
                beside([&] { take(0, chunks / 2); }, [&] { take(chunks / 2, chunks); });
                budget.give_back();
            } else {
                take(0, chunks);
            }
            for (const Side& part : parts) {
                all.bounds.add(part.bounds);
                all.centroids.lo = glm::min(all.centroids.lo, part.centroids.lo);
                all.centroids.hi = glm::max(all.centroids.hi, part.centroids.hi);
            }
        }
        node.bounds = all.bounds;
        if (end - begin == 1) {
            node.leaf = true;
            node.light = order[begin];
            return;
        }
        Side halves[2];
        const size_t mid = split(begin, end, all.bounds, all.centroids, depth, halves);
        node.left = index + 1;
        node.right = index + uint32_t(2 * (mid - begin));
        const uint32_t left = node.left, right = node.right;
        if (mid - begin > kParallelGrain && end - mid > kParallelGrain && budget.take()) {
            // The thread hands its place back as soon as its subtree is done, so that splits
            // still running elsewhere can take it.
            beside(
                [=, &halves] {
                    build(begin, mid, left, depth + 1, &halves[0]);
                    budget.give_back();
                },
                [=, &halves] { build(mid, end, right, depth + 1, &halves[1]); });
        } else {
            build(begin, mid, left, depth + 1, &halves[0]);
            build(mid, end, right, depth + 1, &halves[1]);
        }
        // As the root of a four-wide node: itself and the nodes below its inner slots.
        uint32_t wide = 1;
        for (uint32_t half : {left, right}) {
            const BinaryNode& c = nodes[half];
            if (c.leaf) continue;
            for (uint32_t slot : {c.left, c.right})
                if (!nodes[slot].leaf) wide += nodes[slot].wide_nodes;
        }
        node.wide_nodes = wide;
    }

    // The two sides of a cut at mid, in one pass.
    void sides(size_t begin, size_t mid, size_t end, Side* halves) const {
        for (size_t i = begin; i < end; ++i)
            halves[i < mid ? 0 : 1].add(items[order[i]], centroid[order[i]]);
    }

    // The split of few lights: every cut between them in centroid order on each axis, the
    // SAOH of each from bounds accumulated from both ends (the sweep the bins approximate).
    size_t sweep(size_t begin, size_t end, const glm::dvec3& diagonal, const glm::dvec3& extent,
                 Side* halves) {
        const size_t n = end - begin;
        const double max_extent = std::max({diagonal.x, diagonal.y, diagonal.z});
        double best_cost = std::numeric_limits<double>::infinity();
        size_t best_cut = 0;
        uint32_t best_order[kSweepMax];
        for (int dim = 0; dim < 3; ++dim) {
            if (!(extent[dim] > 0.0)) continue;
            uint32_t sorted[kSweepMax];
            std::copy(order.begin() + long(begin), order.begin() + long(end), sorted);
            std::sort(sorted, sorted + n, [&](uint32_t a, uint32_t b) {
                return centroid[a][dim] < centroid[b][dim] ||
                       (centroid[a][dim] == centroid[b][dim] && a < b);
            });
            const double kr = diagonal[dim] > 0.0 ? max_extent / diagonal[dim] : 1.0;
            thread_local Bounds below[kSweepMax];  // below[i]: sorted[0 .. i]
            below[0] = items[sorted[0]];
            for (size_t i = 1; i + 1 < n; ++i) {
                below[i] = below[i - 1];
                below[i].add_estimate(items[sorted[i]]);
            }
            Bounds above;  // sorted[i + 1 ..]
            for (size_t i = n - 1; i-- > 0;) {
                above.add_estimate(items[sorted[i + 1]]);
                const double cost = saoh_cost(below[i], kr) + saoh_cost(above, kr);
                if (cost < best_cost) {
                    best_cost = cost;
                    best_cut = i + 1;
                    std::copy(sorted, sorted + n, best_order);
                }
            }
        }
        // Every centroid at one point: cut the middle of the order.
        if (best_cut == 0)
            best_cut = n / 2;
        else
            std::copy(best_order, best_order + n, order.begin() + long(begin));
        sides(begin, begin + best_cut, end, halves);
        return begin + best_cut;
    }

    // Where order[begin, end) is cut, with what is known of both sides in halves: the binned
    // SAOH's best bucket boundary, the sweep's best cut for few lights, or the median of the widest
    // centroid axis when no bucket split exists or the path would grow too long. The three axes are
    // binned in one pass.
    size_t split(size_t begin, size_t end, const Bounds& all, const Bounds& centroids, int depth,
                 Side* halves) {
        const size_t n = end - begin;
        if (n == 2) {  // the one split there is
            sides(begin, begin + 1, end, halves);
            return begin + 1;
        }
        // Up to four lights all become slots of one node however they are split (Collapser):
        // the split only pairs them for the node's first cut, and the median pairs neighbours.
        const bool balance = n <= 4 || depth + ceil_log2(n) >= kMaxBinaryDepth;
        const glm::dvec3 diagonal = all.hi - all.lo, extent = centroids.hi - centroids.lo;
        double best_cost = std::numeric_limits<double>::infinity();
        int best_dim = -1, best_bucket = -1;
        glm::dvec3 scale;
        for (int dim = 0; dim < 3; ++dim)
            scale[dim] = extent[dim] > 0.0 ? kBuckets / extent[dim] : 0.0;
        auto bucket_of = [&](uint32_t item, int dim) {
            double t = (centroid[item][dim] - centroids.lo[dim]) * scale[dim];
            return std::clamp(int(t), 0, kBuckets - 1);
        };
        if (!balance && n <= kSweepMax) return sweep(begin, end, diagonal, extent, halves);
        if (!balance) {
            Bins all_bins;
            Bounds(&bucket)[3][kBuckets] = all_bins.bucket;
            size_t(&count)[3][kBuckets] = all_bins.count;
            auto bin = [&](size_t from, size_t to, Bins& bins) {
                for (size_t i = from; i < to; ++i) {
                    const uint32_t item = order[i];
                    for (int dim = 0; dim < 3; ++dim) {
                        if (!(extent[dim] > 0.0)) continue;
                        int b = bucket_of(item, dim);
                        bins.bucket[dim][b].add_estimate(items[item]);
                        ++bins.count[dim][b];
                    }
                }
            };
            if (n <= 2 * kChunk) {
                bin(begin, end, all_bins);
            } else {
                // Many lights (the top levels, which run before there are subtrees to share
                // out): binned in fixed chunks, half of them on a free thread, and merged in
                // chunk order, the same for any number of threads.
                const size_t chunks = (n + kChunk - 1) / kChunk;
                std::vector<Bins> parts(chunks);
                auto bin_chunks = [&](size_t from, size_t to) {
                    for (size_t c = from; c < to; ++c)
                        bin(begin + c * kChunk, std::min(end, begin + (c + 1) * kChunk), parts[c]);
                };
                if (budget.take()) {
                    beside([&] { bin_chunks(0, chunks / 2); },
                           [&] { bin_chunks(chunks / 2, chunks); });
                    budget.give_back();
                } else {
                    bin_chunks(0, chunks);
                }
                for (const Bins& part : parts)
                    for (int dim = 0; dim < 3; ++dim)
                        for (int b = 0; b < kBuckets; ++b) {
                            if (part.count[dim][b] == 0) continue;
                            bucket[dim][b].add_estimate(part.bucket[dim][b]);
                            count[dim][b] += part.count[dim][b];
                        }
            }
            const double max_extent = std::max({diagonal.x, diagonal.y, diagonal.z});
            for (int dim = 0; dim < 3; ++dim) {
                if (!(extent[dim] > 0.0)) continue;
                double kr = diagonal[dim] > 0.0 ? max_extent / diagonal[dim] : 1.0;
                Bounds above[kBuckets];  // above[s]: buckets s .. end
                size_t count_above[kBuckets + 1] = {};
                for (int s = kBuckets - 1; s >= 0; --s) {
                    above[s] = s + 1 < kBuckets ? above[s + 1] : Bounds{};
                    if (count[dim][s] > 0) above[s].add_estimate(bucket[dim][s]);
                    count_above[s] = count_above[s + 1] + count[dim][s];
                }
                Bounds below;
                size_t count_below = 0;
                for (int s = 0; s + 1 < kBuckets; ++s) {
                    // An empty bucket s cuts where the last one did.
                    if (count[dim][s] == 0) continue;
                    below.add_estimate(bucket[dim][s]);
                    count_below += count[dim][s];
                    if (count_above[s + 1] == 0) break;
                    double cost = saoh_cost(below, kr) + saoh_cost(above[s + 1], kr);
                    if (cost < best_cost) {
                        best_cost = cost;
                        best_dim = dim;
                        best_bucket = s;
                    }
                }
            }
        }
        if (best_dim >= 0 && n > 2 * kChunk) {
            // Many lights: partitioned first, then each side's bounds taken on a thread.
            auto it = std::partition(
                order.begin() + long(begin), order.begin() + long(end),
                [&](uint32_t item) { return bucket_of(item, best_dim) <= best_bucket; });
            const size_t mid = size_t(it - order.begin());
            if (mid > begin && mid < end) {
                auto side = [&](size_t from, size_t to, Side& out) {
                    for (size_t i = from; i < to; ++i) out.add(items[order[i]], centroid[order[i]]);
                };
                if (budget.take()) {
                    beside([&] { side(begin, mid, halves[0]); },
                           [&] { side(mid, end, halves[1]); });
                    budget.give_back();
                } else {
                    side(begin, mid, halves[0]);
                    side(mid, end, halves[1]);
                }
                return mid;
            }
        } else if (best_dim >= 0) {
            // Partitioned in place, each light's side taken into that side's bounds as it is
            // decided (so the children need no pass of their own).
            Side decided[2];
            size_t i = begin, j = end;
            while (i < j) {
                const uint32_t item = order[i];
                if (bucket_of(item, best_dim) <= best_bucket) {
                    decided[0].add(items[item], centroid[item]);
                    ++i;
                } else {
                    decided[1].add(items[item], centroid[item]);
                    std::swap(order[i], order[--j]);
                }
            }
            if (i > begin && i < end) {
                halves[0] = decided[0];
                halves[1] = decided[1];
                return i;
            }
        }
        int dim = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
        size_t mid = begin + n / 2;
        std::nth_element(order.begin() + long(begin), order.begin() + long(mid),
                         order.begin() + long(end), [&](uint32_t a, uint32_t b) {
                             return centroid[a][dim] < centroid[b][dim] ||
                                    (centroid[a][dim] == centroid[b][dim] && a < b);
                         });
        sides(begin, mid, end, halves);
        return mid;
    }
};

// One slot of a wide node from the bounds below it.
void set_slot(gpu::LightTreeNode& node, int k, const Bounds& b, uint32_t child, bool leaf) {
    // The centre in float, and the radius about that float centre to the farthest corner of
    // the box, rounded up: the float sphere holds every vertex.
    const glm::dvec3 centre(float(0.5 * (b.lo.x + b.hi.x)), float(0.5 * (b.lo.y + b.hi.y)),
                            float(0.5 * (b.lo.z + b.hi.z)));
    const glm::dvec3 reach = glm::max(centre - b.lo, b.hi - centre);
    // Widened by ε = 1e-6 rad (cos(θ + ε) = cos θ cos ε − sin θ sin ε, −1 past π) and rounded
    // down, so that the float cone still holds every normal.
    const double c = std::clamp(b.normals.cos_theta, -1.0, 1.0), s = std::sqrt(1.0 - c * c);
    const double cos_eps = 0.9999999999995, sin_eps = 1e-6;  // of ε, to double precision
    const double cos_o = s * cos_eps + c * sin_eps < 0.0 ? -1.0 : c * cos_eps - s * sin_eps;
    const float cos_o_f = round_down(cos_o);
    (&node.x.x)[k] = float(centre.x);
    (&node.y.x)[k] = float(centre.y);
    (&node.z.x)[k] = float(centre.z);
    (&node.radius.x)[k] = round_up(glm::length(reach));
    (&node.ax.x)[k] = float(b.normals.w.x);
    (&node.ay.x)[k] = float(b.normals.w.y);
    (&node.az.x)[k] = float(b.normals.w.z);
    (&node.cos_o.x)[k] = cos_o_f;
    (&node.sin_o.x)[k] =
        std::min(1.0f, round_up(std::sqrt(std::max(0.0, 1.0 - double(cos_o_f) * double(cos_o_f)))));
    (&node.cos_e.x)[k] = round_down(b.cos_e);
    (&node.phi.x)[k] = float(b.phi);
    node.child[k] = child;
    if (leaf) node.flags |= LIGHT_SLOT_LEAF << k;
    if (b.two_sided) node.flags |= LIGHT_SLOT_TWO_SIDED << k;
}

gpu::LightTreeNode empty_node() {
    gpu::LightTreeNode node{};
    // No power, and cos θ_e = 1, which no cos θ' exceeds: no importance.
    node.cos_o = node.cos_e = {1.0f, 1.0f, 1.0f, 1.0f};
    return node;
}

// Collapses the binary tree two levels to a node: slots 0, 1 from the first child (itself if a
// leaf, else its two children), slots 2, 3 from the second, so that the kernels' first cut,
// between the two pairs, is the binary split. Nodes are laid out depth first; each subtree's
// node count known from the binary build (BinaryNode::wide_nodes), subtrees are written apart
// (in parallel) into places fixed by the tree alone.
struct Collapser {
    const BinaryNode* binary;
    LightTree& out;
    ThreadBudget& budget;

    // The slots of the node that binary node b becomes.
    int slots_of(uint32_t b, uint32_t* slots, int* used) const {
        int n = 0;
        const uint32_t halves[2] = {binary[b].left, binary[b].right};
        for (int h = 0; h < 2; ++h) {
            const BinaryNode& c = binary[halves[h]];
            used[2 * h] = 1;
            used[2 * h + 1] = c.leaf ? 0 : 1;
            slots[2 * h] = c.leaf ? halves[h] : c.left;
            slots[2 * h + 1] = c.leaf ? 0u : c.right;
            n += c.leaf ? 1 : 2;
        }
        return n;
    }

    void collapse(uint32_t b, uint32_t index, uint32_t trail, uint32_t depth) {
        uint32_t slots[4];
        int used[4];
        slots_of(b, slots, used);
        place(slots, used, index, trail, depth);
    }

    void place(const uint32_t* slots, const int* used, uint32_t index, uint32_t trail,
               uint32_t depth) {
        out.nodes[index] = empty_node();
        uint32_t next = index + 1;
        std::vector<std::thread> threads;
        for (int k = 0; k < 4; ++k) {
            if (!used[k]) continue;
            const BinaryNode& c = binary[slots[k]];
            const uint32_t slot_trail = trail | (uint32_t(k) << (2 * depth));
            if (c.leaf) {
                set_slot(out.nodes[index], k, c.bounds, c.light, true);
                out.paths[c.light] = {slot_trail, depth + 1};
                continue;
            }
            const uint32_t child = next, b = slots[k];
            next += binary[b].wide_nodes;
            set_slot(out.nodes[index], k, c.bounds, child, false);
            if (binary[b].wide_nodes > kParallelGrain && budget.take()) {
                auto task = [=] {
                    collapse(b, child, slot_trail, depth + 1);
                    budget.give_back();
                };
                try {
                    threads.emplace_back(task);
                } catch (const std::system_error&) {
                    task();
                }
            } else {
                collapse(b, child, slot_trail, depth + 1);
            }
        }
        for (std::thread& t : threads) t.join();
    }
};

}  // namespace

LightTree build_light_tree(const std::vector<gpu::Light>& lights, const std::vector<double>& powers,
                           int threads, const std::vector<LightTreeItem>& more) {
    LightTree tree;
    const size_t total = lights.size() + more.size();
    tree.paths.assign(total, gpu::LightTreePath{0u, 0u});
    // A punctual light's box, for its centre: its corners as the triangle's three vertices.
    auto vertices = [&](size_t i, glm::dvec3* p) {
        if (i >= lights.size()) {
            const LightTreeItem& item = more[i - lights.size()];
            p[0] = item.lo;
            p[1] = p[2] = item.hi;
            return;
        }
        const gpu::Light& l = lights[i];
        p[0] = {l.p0.x, l.p0.y, l.p0.z};
        p[1] = {l.p1.x, l.p1.y, l.p1.z};
        p[2] = {l.p2.x, l.p2.y, l.p2.z};
    };
    // The lights with power in Morton order of their centroids (Morton 1966): a subtree's
    // lights then lie together in memory, which the splits' passes over them read in far fewer
    // cache lines.
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<glm::dvec3> centre(total);
    std::mutex box_mutex;
    Bounds box;  // of the centres (min and max: the same in any order)
    parallel_for(threads, total, [&](size_t begin, size_t end) {
        Bounds part;
        for (size_t i = begin; i < end; ++i) {
            if (!(powers[i] > 0.0)) continue;
            glm::dvec3 p[3];
            vertices(i, p);
            centre[i] =
                0.5 * (glm::min(p[0], glm::min(p[1], p[2])) + glm::max(p[0], glm::max(p[1], p[2])));
            part.lo = glm::min(part.lo, centre[i]);
            part.hi = glm::max(part.hi, centre[i]);
        }
        std::lock_guard<std::mutex> lock(box_mutex);
        box.lo = glm::min(box.lo, part.lo);
        box.hi = glm::max(box.hi, part.hi);
    });
    std::vector<uint64_t> keys;
    keys.reserve(total);
    for (size_t i = 0; i < total; ++i)
        if (powers[i] > 0.0) keys.push_back(i);
    if (keys.empty()) return tree;
    const glm::dvec3 extent = glm::max(box.hi - box.lo, glm::dvec3(1e-300));
    auto spread = [](uint32_t v) {  // the 10 bits of v, two zero bits between each
        v = (v | (v << 16)) & 0x030000FFu;
        v = (v | (v << 8)) & 0x0300F00Fu;
        v = (v | (v << 4)) & 0x030C30C3u;
        return (v | (v << 2)) & 0x09249249u;
    };
    parallel_for(threads, keys.size(), [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
            const glm::dvec3 t = (centre[keys[k]] - box.lo) / extent * 1023.0;
            const uint32_t code =
                spread(uint32_t(t.x)) | (spread(uint32_t(t.y)) << 1) | (spread(uint32_t(t.z)) << 2);
            keys[k] |= uint64_t(code) << 32;
        }
    });
    // Sorted in two halves at once, then merged (the keys are distinct: the same order).
    {
        const auto middle = keys.begin() + long(keys.size() / 2);
        beside([&] { std::sort(keys.begin(), middle); }, [&] { std::sort(middle, keys.end()); });
        std::inplace_merge(keys.begin(), middle, keys.end());
    }
    // Item k: the bounds of light light_of[k].
    const size_t count = keys.size();
    // Storage for the items, each constructed by the part that fills it (pages first touched
    // in parallel).
    using ItemStorage = std::aligned_storage_t<sizeof(Bounds), alignof(Bounds)>;
    static_assert(std::is_trivially_destructible_v<Bounds>);
    std::unique_ptr<ItemStorage[]> item_storage(new ItemStorage[count]);
    Bounds* items = reinterpret_cast<Bounds*>(item_storage.get());
    std::vector<glm::dvec3> centroid(count);
    std::vector<uint32_t> light_of(count), order(count);
    parallel_for(threads, count, [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
            const uint32_t i = uint32_t(keys[k]);
            centroid[k] = centre[i];
            light_of[k] = i;
            order[k] = uint32_t(k);
            if (i >= lights.size()) {
                const LightTreeItem& item = more[i - lights.size()];
                Bounds& b = *new (&items[k]) Bounds();
                b.lo = item.lo;
                b.hi = item.hi;
                b.phi = item.phi;
                b.normals = item.cos_o <= -1.0 ? whole_sphere(item.axis)
                                               : Cone{item.axis, item.cos_o, false};
                b.cos_e = item.cos_e;
                continue;
            }
            glm::dvec3 p[3];
            vertices(i, p);
            const glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
            const double length = glm::length(normal);
            Bounds& b = *new (&items[k]) Bounds();
            b.lo = glm::min(p[0], glm::min(p[1], p[2]));
            b.hi = glm::max(p[0], glm::max(p[1], p[2]));
            b.phi = powers[i];
            // An area light: its normal, emitting over the hemisphere (θ_o = 0, θ_e = π/2), on
            // both sides when double-sided (pbrt-v4's DiffuseAreaLight::Bounds).
            // A sliver whose normal is lost to rounding may emit anywhere: the whole sphere.
            b.normals = length > 0.0 ? Cone{normal / length, 1.0, false} : whole_sphere({0, 0, 1});
            b.cos_e = 0.0;
            b.two_sided = (lights[i].flags & MATERIAL_DOUBLE_SIDED) != 0u;
        }
    });
    const size_t binary_count = 2 * order.size() - 1;
    using Storage = std::aligned_storage_t<sizeof(BinaryNode), alignof(BinaryNode)>;
    static_assert(std::is_trivially_destructible_v<BinaryNode>);
    std::unique_ptr<Storage[]> storage(new Storage[binary_count]);  // not initialised
    BinaryNode* binary = reinterpret_cast<BinaryNode*>(storage.get());
    ThreadBudget budget(threads - 1);
    BinaryBuilder builder{items, centroid, order, binary, budget};
    builder.build(0, order.size(), 0u, 0, nullptr);
    parallel_for(threads, binary_count, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            if (binary[i].leaf) binary[i].light = light_of[binary[i].light];
    });
    Collapser collapser{binary, tree, budget};
    if (binary[0].leaf) {  // one light: a root of one slot
        const uint32_t slots[4] = {0u, 0u, 0u, 0u};
        const int used[4] = {1, 0, 0, 0};
        tree.nodes.resize(1);
        collapser.place(slots, used, 0u, 0u, 0u);
    } else {
        tree.nodes.resize(binary[0].wide_nodes);
        collapser.collapse(0u, 0u, 0u, 0u);
    }
    return tree;
}

std::vector<uint32_t> light_tree_words(const LightTree& tree) {
    const size_t nodes = std::max<size_t>(tree.nodes.size(), 1);  // an empty tree: one zero node
    std::vector<uint32_t> words(
        (nodes * sizeof(gpu::LightTreeNode) + tree.paths.size() * sizeof(gpu::LightTreePath)) /
            sizeof(uint32_t),
        0u);
    if (!tree.nodes.empty())
        std::memcpy(words.data(), tree.nodes.data(),
                    tree.nodes.size() * sizeof(gpu::LightTreeNode));
    if (!tree.paths.empty())
        std::memcpy(words.data() + nodes * sizeof(gpu::LightTreeNode) / sizeof(uint32_t),
                    tree.paths.data(), tree.paths.size() * sizeof(gpu::LightTreePath));
    return words;
}

}  // namespace mcrt
