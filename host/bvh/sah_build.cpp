// Binned SAH BVH build over triangle centroids (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"; PBRT 3rd ed. 4.3), flattened depth-first with siblings adjacent,
// then collapsed into the 4-wide tree of bvh4_collapse.cpp.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "bvh/bvh.h"
#include "common/error.h"

namespace mcrt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Bounds of an empty root: inverted but finite, as kernels may assume no infinities.
constexpr float kHuge = 1e30f;

// Four floats (x, y, z, unused w = 0) in a GCC/Clang vector: one SSE/NEON op per box update.
typedef float V4 __attribute__((vector_size(16)));
typedef int32_t V4i __attribute__((vector_size(16)));

V4 vmin(V4 a, V4 b) { return a < b ? a : b; }
V4 vmax(V4 a, V4 b) { return a > b ? a : b; }

// Axis-aligned box; an empty box is inverted (lo = +inf, hi = -inf) and never a point, so a union
// with it changes nothing (an empty box merged as a point would stretch every box above it to
// that point, and traversal would visit them for nothing: docs/BENCHMARKS.md "BVH build").
struct Bounds {
    V4 lo = {kInf, kInf, kInf, 0.0f};
    V4 hi = {-kInf, -kInf, -kInf, 0.0f};

    void grow(V4 b_lo, V4 b_hi) {
        lo = vmin(lo, b_lo);
        hi = vmax(hi, b_hi);
    }
    void grow(const Bounds& b) { grow(b.lo, b.hi); }
    void grow_point(V4 p) { grow(p, p); }

    // Surface area in double, which cannot overflow (PBRT 2.1.3); 0 for an empty box.
    double area() const {
        double d[3];
        for (int k = 0; k < 3; ++k) {
            d[k] = double(hi[k]) - double(lo[k]);
            if (!(d[k] >= 0.0)) return 0.0;
        }
        return 2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
    }
};

// A triangle's bounds, 32 bytes, partitioned in place so that each node's are contiguous.
// Centroids are kept doubled (lo + hi) to save a multiply; binning is invariant to the scale.
struct PrimRef {
    V4 lo, hi;
    V4 centroid2() const { return lo + hi; }
};

// A node whose subtree is still to be built over refs[begin, end).
struct Task {
    uint32_t begin, end;
    uint32_t node;
    int level;    // the root is level 1
    Bounds cbox;  // bounds of the doubled centroids
};

// Levels a subtree of n triangles needs when built with median splits: 1 + ceil(log2(ceil(n/m))).
int levels_needed(uint64_t n, uint64_t max_leaf) {
    int levels = 1;
    for (uint64_t leaves = (n + max_leaf - 1) / max_leaf; leaves > 1; leaves = (leaves + 1) / 2)
        ++levels;
    return levels;
}

// Bins of a doubled centroid on the three axes; NaN-safe and clamped to [0, bins - 1]. Binning
// and partitioning both call this, so each side of a plane gets exactly the triangles counted.
V4i bins_of(V4 centroid2, V4 origin, V4 scale, V4 last_bin) {
    V4 f = (centroid2 - origin) * scale;
    f = f > 0.0f ? f : V4{};
    f = f < last_bin ? f : last_bin;
    return __builtin_convertvector(f, V4i);
}

struct SahSplit {
    int axis = -1;
    int bin = 0;  // bins 0..bin go left
    V4 scale{};   // bins per unit of doubled centroid, 0 on flat axes
    double cost = std::numeric_limits<double>::infinity();  // A_L·N_L + A_R·N_R, not divided by A
};

// What one building thread writes besides its nodes: bins reused by every node it splits (empty
// between nodes), sweep arrays, and the deepest leaf level it made.
struct Scratch {
    explicit Scratch(int bins)
        : bin_box(3 * size_t(bins)),
          bin_count(3 * size_t(bins)),
          right_area(size_t(bins)),
          right_count(size_t(bins)) {}
    std::vector<Bounds> bin_box;  // bins per axis
    std::vector<uint32_t> bin_count;
    std::vector<double> right_area;
    std::vector<uint32_t> right_count;
    int depth = 0;
};

// Scenes smaller than this are built on one thread: threads would cost more than they save.
constexpr uint32_t kParallelMinTriangles = 65536;

bool is_inner(const gpu::BvhNode& node) { return gpu::as_uint(node.hi.w) == 0; }

// Moves an inner node's child index by `offset`; leaves index triangles and stay.
gpu::BvhNode shifted(gpu::BvhNode node, uint32_t offset) {
    if (is_inner(node)) {
        node.lo.w = gpu::as_float(gpu::as_uint(node.lo.w) + offset);
    }
    return node;
}

class Builder {
  public:
    Builder(const Scene& scene, const BvhBuildOptions& options)
        : scene_(scene),
          bins_(options.bins),
          max_leaf_(uint32_t(options.max_leaf_size)),
          traversal_cost_(options.traversal_cost),
          split_budget_(options.spatial_split_budget) {}

    Bvh build();

  private:
    Bounds make_refs();
    void build_subtree(Task root, std::vector<gpu::BvhNode>& nodes, Scratch& scratch,
                       uint32_t defer_at_most, std::vector<Task>* deferred);
    std::vector<gpu::BvhNode> build_parallel(const Task& root, const gpu::BvhNode& root_node,
                                             unsigned threads, int& depth);
    SahSplit find_sah_split(const PrimRef* refs, const Task& task, Scratch& scratch);
    uint32_t partition_sah(PrimRef* refs, uint32_t* ids, const Task& task, const SahSplit& split,
                           Bounds child_box[2], Bounds child_cbox[2]);
    // Spatial splits (Stich, Friedrich, Dietrich 2009, "Spatial splits in bounding volume
    // hierarchies"): the tree over references, a triangle's clipped pieces, laid out as
    // build_subtree lays out its nodes; refs_ and ids_ end in leaf order.
    void build_spatial(const gpu::BvhNode& root_node, const Bounds& root_cbox,
                       std::vector<gpu::BvhNode>& nodes, int& depth);
    void build_spatial_node(std::vector<PrimRef>& refs, std::vector<uint32_t>& ids, uint32_t node,
                            int level, const Bounds& cbox, std::vector<gpu::BvhNode>& nodes,
                            Scratch& scratch, std::vector<PrimRef>& out_refs,
                            std::vector<uint32_t>& out_ids, int& depth);
    Bounds clipped(uint32_t id, const PrimRef& ref, int axis, float lo, float hi) const;
    uint32_t partition_median(PrimRef* refs, uint32_t* ids, const Task& task, Bounds child_box[2],
                              Bounds child_cbox[2]);
    void fill_stats(Bvh& bvh, int depth) const;

    const Scene& scene_;
    int bins_;
    uint32_t max_leaf_;
    float traversal_cost_;
    float split_budget_;         // extra references allowed, as a fraction of the triangles
    size_t extra_refs_ = 0;      // references added by spatial splits so far
    double root_area_ = 0.0;     // the root box's area, for the overlap test
    std::vector<PrimRef> refs_;  // threads own disjoint ranges of refs_ and ids_
    std::vector<uint32_t> ids_;  // scene triangle of refs_[i], permuted alongside
};

void set_box(gpu::BvhNode& node, const Bounds& box) {
    node.lo.x = box.lo[0];
    node.lo.y = box.lo[1];
    node.lo.z = box.lo[2];
    node.hi.x = box.hi[0];
    node.hi.y = box.hi[1];
    node.hi.z = box.hi[2];
}

void set_first_count(gpu::BvhNode& node, uint32_t first, uint32_t count) {
    node.lo.w = gpu::as_float(first);
    node.hi.w = gpu::as_float(count);
}

Bounds node_box(const gpu::BvhNode& node) {
    Bounds b;
    b.lo = V4{node.lo.x, node.lo.y, node.lo.z, 0.0f};
    b.hi = V4{node.hi.x, node.hi.y, node.hi.z, 0.0f};
    return b;
}

// Precomputes every triangle's bounds; returns the bounds of all (doubled) centroids.
Bounds Builder::make_refs() {
    const size_t n = scene_.triangle_count();
    refs_.resize(n);
    ids_.resize(n);
    Bounds cbox;
    for (size_t t = 0; t < n; ++t) {
        const glm::vec3* p = &scene_.positions[3 * t];
        V4 a = {p[0].x, p[0].y, p[0].z, 0.0f}, b = {p[1].x, p[1].y, p[1].z, 0.0f},
           c = {p[2].x, p[2].y, p[2].z, 0.0f};
        PrimRef& r = refs_[t];
        r.lo = vmin(a, vmin(b, c));
        r.hi = vmax(a, vmax(b, c));
        ids_[t] = uint32_t(t);
        cbox.grow_point(r.centroid2());
    }
    return cbox;
}

// Bins the centroids of the task on all three axes and sweeps for the cheapest plane (Wald 2007
// §3).
SahSplit Builder::find_sah_split(const PrimRef* refs, const Task& task, Scratch& scratch) {
    SahSplit best;
    for (int k = 0; k < 3; ++k) {
        float extent = task.cbox.hi[k] - task.cbox.lo[k];
        float s = float(bins_) / extent;
        // A flat axis (or one too thin for its scale to be finite) puts everything in bin 0.
        best.scale[k] = (extent > 0.0f && s < kInf) ? s : 0.0f;
    }
    const V4 scale = best.scale, origin = task.cbox.lo;
    const V4 last_bin = V4{} + float(bins_ - 1);
    // Bins are all empty here: each sweep below empties the ones it used.
    const size_t b1 = size_t(bins_), b2 = 2 * size_t(bins_);
    Bounds* box[3] = {&scratch.bin_box[0], &scratch.bin_box[b1], &scratch.bin_box[b2]};
    uint32_t* count[3] = {&scratch.bin_count[0], &scratch.bin_count[b1], &scratch.bin_count[b2]};
    double* right_area = scratch.right_area.data();
    uint32_t* right_count = scratch.right_count.data();
    V4i used_lo = V4i{} + bins_, used_hi = V4i{};
    for (uint32_t i = task.begin; i < task.end; ++i) {
        const PrimRef& r = refs[i];
        const V4i b = bins_of(r.centroid2(), origin, scale, last_bin);
        used_lo = b < used_lo ? b : used_lo;
        used_hi = b > used_hi ? b : used_hi;
        for (int k = 0; k < 3; ++k) {
            box[k][b[k]].grow(r.lo, r.hi);
            ++count[k][b[k]];
        }
    }

    for (int k = 0; k < 3; ++k) {
        const int first = used_lo[k], last = used_hi[k];
        if (first == last) {  // one bin (always so on a flat axis): no plane splits it
            box[k][first] = Bounds{};
            count[k][first] = 0;
            continue;
        }
        // Right-to-left sweep: right_*[i] describe bins i+1 .. last; empty bins change nothing.
        Bounds acc;
        uint32_t n = 0;
        double area = 0.0;
        for (int i = last; i > first; --i) {
            if (count[k][i] > 0) {
                acc.grow(box[k][i]);
                n += count[k][i];
                area = acc.area();
            }
            right_area[i - 1] = area;
            right_count[i - 1] = n;
        }
        // Left-to-right sweep over planes first+1 .. last, each with triangles on both sides.
        acc = Bounds{};
        n = 0;
        area = 0.0;
        for (int i = first; i < last; ++i) {
            if (count[k][i] > 0) {
                acc.grow(box[k][i]);
                n += count[k][i];
                area = acc.area();
                box[k][i] = Bounds{};
                count[k][i] = 0;
            }
            const double cost = area * packets_for(n) + right_area[i] * packets_for(right_count[i]);
            if (cost < best.cost) {
                best.axis = k;
                best.bin = i;
                best.cost = cost;
            }
        }
        box[k][last] = Bounds{};
        count[k][last] = 0;
    }
    return best;
}

// Partitions refs[begin, end) in place by the plane of `split` (the binning's own bins_of, so the
// sides match the bin counts) and bounds both sides; returns the first index on the right.
uint32_t Builder::partition_sah(PrimRef* refs, uint32_t* ids, const Task& task,
                                const SahSplit& split, Bounds child_box[2], Bounds child_cbox[2]) {
    const int k = split.axis;
    const V4 last_bin = V4{} + float(bins_ - 1);
    auto is_left = [&](const PrimRef& r) {
        return bins_of(r.centroid2(), task.cbox.lo, split.scale, last_bin)[k] <= split.bin;
    };
    auto add = [&](uint32_t i, int side) {
        child_box[side].grow(refs[i].lo, refs[i].hi);
        child_cbox[side].grow_point(refs[i].centroid2());
    };
    uint32_t i = task.begin, j = task.end;
    for (;;) {
        while (i < j && is_left(refs[i])) add(i++, 0);
        while (i < j && !is_left(refs[j - 1])) add(--j, 1);
        if (i >= j) break;
        std::swap(refs[i], refs[j - 1]);
        std::swap(ids[i], ids[j - 1]);
        add(i++, 0);
        add(--j, 1);
    }
    return i;
}

// Splits refs[begin, end) at the middle index, ordered along the widest centroid axis (object
// median).
uint32_t Builder::partition_median(PrimRef* refs, uint32_t* ids, const Task& task,
                                   Bounds child_box[2], Bounds child_cbox[2]) {
    int k = 0;
    for (int a = 1; a < 3; ++a)
        if (task.cbox.hi[a] - task.cbox.lo[a] > task.cbox.hi[k] - task.cbox.lo[k]) k = a;
    const uint32_t mid = task.begin + (task.end - task.begin) / 2;
    if (task.cbox.hi[k] > task.cbox.lo[k]) {
        // Sort indices, then apply the permutation to refs and ids alike.
        std::vector<uint32_t> order(task.end - task.begin);
        for (uint32_t i = 0; i < order.size(); ++i) order[i] = task.begin + i;
        std::nth_element(order.begin(), order.begin() + (mid - task.begin), order.end(),
                         [&](uint32_t a, uint32_t b) {
                             return refs[a].centroid2()[k] < refs[b].centroid2()[k];
                         });
        std::vector<PrimRef> sorted_refs(order.size());
        std::vector<uint32_t> sorted_ids(order.size());
        for (size_t i = 0; i < order.size(); ++i)
            sorted_refs[i] = refs[order[i]], sorted_ids[i] = ids[order[i]];
        std::copy(sorted_refs.begin(), sorted_refs.end(), refs + task.begin);
        std::copy(sorted_ids.begin(), sorted_ids.end(), ids + task.begin);
    }
    for (int side = 0; side < 2; ++side) child_box[side] = child_cbox[side] = Bounds{};
    for (uint32_t i = task.begin; i < task.end; ++i) {
        const int side = i < mid ? 0 : 1;
        child_box[side].grow(refs[i].lo, refs[i].hi);
        child_cbox[side].grow_point(refs[i].centroid2());
    }
    return mid;
}

// Builds the subtree under nodes[root.node] depth-first, appending children in adjacent pairs;
// with `deferred`, tasks of at most defer_at_most triangles are left to it instead.
void Builder::build_subtree(Task root, std::vector<gpu::BvhNode>& nodes, Scratch& scratch,
                            uint32_t defer_at_most, std::vector<Task>* deferred) {
    std::vector<Task> stack{root};
    while (!stack.empty()) {
        const Task task = stack.back();
        stack.pop_back();
        const uint32_t count = task.end - task.begin;
        if (deferred && count <= defer_at_most) {
            deferred->push_back(task);
            continue;
        }
        // Levels left below this node; the depth guard below keeps levels_needed(count) ≤ budget
        // + 1.
        const int budget = kMaxBvhDepth - task.level;
        bool leaf = count <= 1 || budget <= 0;
        SahSplit split;
        if (!leaf) {
            // Leaf when it costs no more than the best split (PBRT 4.3.2); never above
            // max_leaf_size.
            const double area = node_box(nodes[task.node]).area();
            split = find_sah_split(refs_.data(), task, scratch);
            leaf = count <= max_leaf_ &&
                   (split.axis < 0 ||
                    double(packets_for(count)) * area <= traversal_cost_ * area + split.cost);
        }
        if (leaf) {
            set_first_count(nodes[task.node], task.begin, count);
            scratch.depth = std::max(scratch.depth, task.level);
            continue;
        }

        Bounds child_box[2], child_cbox[2];
        uint32_t mid = task.end;
        if (split.axis >= 0)
            mid = partition_sah(refs_.data(), ids_.data(), task, split, child_box, child_cbox);
        // Coincident centroids, or an SAH split too lopsided for the depth left: median split.
        const uint32_t larger = std::max(mid - task.begin, task.end - mid);
        if (mid == task.begin || mid == task.end || levels_needed(larger, max_leaf_) > budget)
            mid = partition_median(refs_.data(), ids_.data(), task, child_box, child_cbox);

        const uint32_t left = uint32_t(nodes.size());
        set_first_count(nodes[task.node], left, 0);
        nodes.emplace_back();
        nodes.emplace_back();
        set_box(nodes[left], child_box[0]);
        set_box(nodes[left + 1], child_box[1]);
        // Left child popped first: a depth-first layout.
        stack.push_back(Task{mid, task.end, left + 1, task.level + 1, child_cbox[1]});
        stack.push_back(Task{task.begin, mid, left, task.level + 1, child_cbox[0]});
    }
}

// The top of the tree on this thread, its subtrees on all threads, then spliced in the order a
// single thread lays them out, so the result is the same bits whatever the number of threads.
std::vector<gpu::BvhNode> Builder::build_parallel(const Task& root, const gpu::BvhNode& root_node,
                                                  unsigned threads, int& depth) {
    const uint32_t n = root.end - root.begin;
    std::vector<gpu::BvhNode> top{root_node};
    std::vector<Task> deferred;
    Scratch top_scratch(bins_);
    build_subtree(root, top, top_scratch, std::max<uint32_t>(n / (8 * threads), 4096), &deferred);
    depth = top_scratch.depth;

    // Each deferred subtree in its own array whose node 0 is the subtree's root; largest first.
    std::vector<std::vector<gpu::BvhNode>> subtrees(deferred.size());
    std::vector<size_t> order(deferred.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return deferred[a].end - deferred[a].begin > deferred[b].end - deferred[b].begin;
    });
    std::atomic<size_t> next{0};
    std::vector<int> depths(threads, 0);
    // A failure (out of memory) in any thread stops the others at their next subtree and is
    // rethrown once every thread has been joined.
    std::vector<std::exception_ptr> failures(threads);
    auto work = [&](unsigned thread) {
        try {
            Scratch scratch(bins_);
            for (size_t i; (i = next.fetch_add(1)) < order.size();) {
                const size_t d = order[i];
                std::vector<gpu::BvhNode>& nodes = subtrees[d];
                Task task = deferred[d];
                nodes.reserve(2 * size_t(task.end - task.begin) - 1);
                nodes.push_back(top[task.node]);
                task.node = 0;
                build_subtree(task, nodes, scratch, 0, nullptr);
            }
            depths[thread] = scratch.depth;
        } catch (...) {
            failures[thread] = std::current_exception();
            next = order.size();
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) {
        try {
            pool.emplace_back(work, t);
        } catch (const std::system_error&) {
            break;  // no more threads to be had: those running share the rest
        }
    }
    work(0);
    for (std::thread& t : pool) t.join();
    for (const std::exception_ptr& failure : failures)
        if (failure) std::rethrow_exception(failure);
    for (int d : depths) depth = std::max(depth, d);

    // Splice: walk the top depth-first, giving each node's children the next pair of slots.
    std::vector<int> subtree_of(top.size(), -1);
    for (size_t d = 0; d < deferred.size(); ++d) subtree_of[deferred[d].node] = int(d);
    std::vector<gpu::BvhNode> nodes;
    nodes.reserve(2 * size_t(n) - 1);
    nodes.push_back(top[0]);
    std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, 0u}};  // (index in top, in nodes)
    while (!stack.empty()) {
        const auto [t, f] = stack.back();
        stack.pop_back();
        if (subtree_of[t] >= 0) {
            // A subtree's descendants follow contiguously: its node j ≥ 1 goes to base + j - 1.
            const std::vector<gpu::BvhNode>& sub = subtrees[size_t(subtree_of[t])];
            const uint32_t offset = uint32_t(nodes.size()) - 1;
            nodes[f] = shifted(sub[0], offset);
            for (size_t j = 1; j < sub.size(); ++j) nodes.push_back(shifted(sub[j], offset));
        } else if (is_inner(top[t])) {
            const uint32_t first = gpu::as_uint(top[t].lo.w);
            const uint32_t c = uint32_t(nodes.size());
            nodes[f].lo.w = gpu::as_float(c);
            nodes.push_back(top[first]);
            nodes.push_back(top[first + 1]);
            stack.push_back({first + 1, c + 1});
            stack.push_back({first, c});
        }
    }
    return nodes;
}

// The bounds of triangle `id` clipped to the slab lo ≤ x[axis] ≤ hi, within the reference's own
// bounds (a piece of an earlier split): the vertices inside the slab and the points where the
// edges cross its planes (Stich et al. 2009, sec. 4.2). Empty (inverted) when nothing is left.
Bounds Builder::clipped(uint32_t id, const PrimRef& ref, int axis, float lo, float hi) const {
    const glm::vec3* p = &scene_.positions[3 * size_t(id)];
    Bounds b;
    for (int e = 0; e < 3; ++e) {
        const glm::vec3 u = p[e], v = p[(e + 1) % 3];
        const float a = u[axis], c = v[axis];
        if (a >= lo && a <= hi) b.grow_point(V4{u.x, u.y, u.z, 0.0f});
        for (float plane : {lo, hi}) {
            if ((a < plane && c > plane) || (a > plane && c < plane)) {
                const float t = (plane - a) / (c - a);
                glm::vec3 x = u + (v - u) * t;
                x[axis] = plane;
                b.grow_point(V4{x.x, x.y, x.z, 0.0f});
            }
        }
    }
    b.lo = vmax(b.lo, ref.lo);
    b.hi = vmin(b.hi, ref.hi);
    b.lo[axis] = std::max(b.lo[axis], lo);
    b.hi[axis] = std::min(b.hi[axis], hi);
    for (int k = 0; k < 3; ++k)
        if (!(b.lo[k] <= b.hi[k])) return Bounds{};
    return b;
}

namespace {
bool is_empty(const Bounds& b) { return !(b.lo[0] <= b.hi[0]); }
Bounds overlap(const Bounds& a, const Bounds& b) {
    Bounds o;
    o.lo = vmax(a.lo, b.lo);
    o.hi = vmin(a.hi, b.hi);
    return o;
}
Bounds merged(Bounds a, const Bounds& b) {
    a.grow(b);
    return a;
}
}  // namespace

void Builder::build_spatial_node(std::vector<PrimRef>& refs, std::vector<uint32_t>& ids,
                                 uint32_t node, int level, const Bounds& cbox,
                                 std::vector<gpu::BvhNode>& nodes, Scratch& scratch,
                                 std::vector<PrimRef>& out_refs, std::vector<uint32_t>& out_ids,
                                 int& depth) {
    const uint32_t count = uint32_t(refs.size());
    const int budget = kMaxBvhDepth - level;
    const Bounds box = node_box(nodes[node]);
    const double area = box.area();
    Task task{0, count, node, level, cbox};
    bool leaf = count <= 1 || budget <= 0;
    SahSplit split;
    Bounds child_box[2], child_cbox[2];
    uint32_t mid = count;
    // The spatial split, when it wins: the plane and its side's references.
    std::vector<PrimRef> side_refs[2];
    std::vector<uint32_t> side_ids[2];
    bool spatial = false;
    int spatial_axis = -1;
    float spatial_plane = 0.0f;
    if (!leaf) {
        split = find_sah_split(refs.data(), task, scratch);
        double best_cost = split.cost;
        if (split.axis >= 0)
            mid = partition_sah(refs.data(), ids.data(), task, split, child_box, child_cbox);
        const double lambda =
            split.axis >= 0 ? overlap(child_box[0], child_box[1]).area() : root_area_;
        const size_t allowed = size_t(double(split_budget_) * double(scene_.triangle_count()));
        // Spatial splits only where the object split's children overlap (Stich et al. sec. 4.3,
        // α = 1e-5) and while the reference budget lasts.
        if (lambda > 1e-5 * root_area_ && extra_refs_ < allowed) {
            const int bins = bins_;
            for (int k = 0; k < 3; ++k) {
                const float lo = box.lo[k], extent = box.hi[k] - lo;
                if (!(extent > 0.0f)) continue;
                const float scale = float(bins) / extent;
                std::vector<Bounds> bin_box(static_cast<size_t>(bins));
                std::vector<uint32_t> entry(static_cast<size_t>(bins)),
                    exit(static_cast<size_t>(bins));
                auto bin_of = [&](float x) {
                    return std::min(bins - 1, std::max(0, int((x - lo) * scale)));
                };
                auto plane = [&](int i) { return lo + float(i) * extent / float(bins); };
                for (uint32_t i = 0; i < count; ++i) {
                    const PrimRef& r = refs[i];
                    const int first = bin_of(r.lo[k]), last = bin_of(r.hi[k]);
                    ++entry[size_t(first)];
                    ++exit[size_t(last)];
                    if (first == last) {
                        bin_box[size_t(first)].grow(r.lo, r.hi);
                        continue;
                    }
                    for (int b = first; b <= last; ++b)
                        bin_box[size_t(b)].grow(clipped(ids[i], r, k, plane(b), plane(b + 1)));
                }
                std::vector<double> right_area(static_cast<size_t>(bins));
                std::vector<uint32_t> right_count(static_cast<size_t>(bins));
                Bounds acc;
                uint32_t n = 0;
                for (int i = bins - 1; i > 0; --i) {
                    acc.grow(bin_box[size_t(i)]);
                    n += exit[size_t(i)];
                    right_area[size_t(i - 1)] = acc.area();
                    right_count[size_t(i - 1)] = n;
                }
                acc = Bounds{};
                n = 0;
                for (int i = 0; i < bins - 1; ++i) {
                    acc.grow(bin_box[size_t(i)]);
                    n += entry[size_t(i)];
                    if (n == 0 || right_count[size_t(i)] == 0) continue;
                    const double cost = acc.area() * packets_for(n) +
                                        right_area[size_t(i)] * packets_for(right_count[size_t(i)]);
                    if (cost < best_cost) {
                        best_cost = cost;
                        spatial = true;
                        spatial_axis = k;
                        spatial_plane = plane(i + 1);
                    }
                }
            }
        }
        leaf = count <= max_leaf_ &&
               ((split.axis < 0 && !spatial) ||
                double(packets_for(count)) * area <= traversal_cost_ * area + best_cost);
    }
    if (!leaf && spatial) {
        // References wholly on one side go there; the others are split at the plane, or kept
        // whole on one side where that costs less (reference unsplitting, Stich et al. 4.4).
        const int k = spatial_axis;
        const float x = spatial_plane;
        Bounds side_box[2];
        std::vector<uint32_t> straddling;
        for (uint32_t i = 0; i < count; ++i) {
            const PrimRef& r = refs[i];
            if (r.hi[k] <= x) {
                side_refs[0].push_back(r), side_ids[0].push_back(ids[i]);
                side_box[0].grow(r.lo, r.hi);
            } else if (r.lo[k] >= x) {
                side_refs[1].push_back(r), side_ids[1].push_back(ids[i]);
                side_box[1].grow(r.lo, r.hi);
            } else {
                straddling.push_back(i);
            }
        }
        // Boxes and counts as if every straddling reference were split.
        std::vector<Bounds> pieces[2];
        for (uint32_t i : straddling) {
            pieces[0].push_back(clipped(ids[i], refs[i], k, -kInf, x));
            pieces[1].push_back(clipped(ids[i], refs[i], k, x, kInf));
        }
        Bounds all_box[2] = {side_box[0], side_box[1]};
        uint32_t n[2] = {uint32_t(side_refs[0].size()), uint32_t(side_refs[1].size())};
        for (size_t j = 0; j < straddling.size(); ++j)
            for (int side = 0; side < 2; ++side)
                if (!is_empty(pieces[side][j])) all_box[side].grow(pieces[side][j]), ++n[side];
        for (size_t j = 0; j < straddling.size(); ++j) {
            const uint32_t i = straddling[j];
            const PrimRef& r = refs[i];
            Bounds whole;
            whole.grow(r.lo, r.hi);
            const double c_split =
                all_box[0].area() * packets_for(n[0]) + all_box[1].area() * packets_for(n[1]);
            const double c_left = merged(all_box[0], whole).area() * packets_for(n[0]) +
                                  all_box[1].area() * packets_for(n[1] - 1);
            const double c_right = all_box[0].area() * packets_for(n[0] - 1) +
                                   merged(all_box[1], whole).area() * packets_for(n[1]);
            const bool empty0 = is_empty(pieces[0][j]), empty1 = is_empty(pieces[1][j]);
            if (empty0 || empty1 || c_left < c_split || c_right < c_split) {
                const int side = empty1 ? 0 : empty0 ? 1 : c_left <= c_right ? 0 : 1;
                side_refs[side].push_back(r), side_ids[side].push_back(ids[i]);
                if (!empty0 && !empty1) {
                    all_box[side].grow(whole);
                    --n[1 - side];
                }
            } else {
                for (int side = 0; side < 2; ++side) {
                    PrimRef piece{pieces[side][j].lo, pieces[side][j].hi};
                    side_refs[side].push_back(piece), side_ids[side].push_back(ids[i]);
                }
            }
        }
        const uint32_t nl = uint32_t(side_refs[0].size()), nr = uint32_t(side_refs[1].size());
        if (nl == 0 || nr == 0 || nl >= count || nr >= count ||
            levels_needed(std::max(nl, nr), max_leaf_) > budget) {
            spatial = false;  // no progress, or too deep: the object split below instead
            side_refs[0].clear(), side_refs[1].clear(), side_ids[0].clear(), side_ids[1].clear();
        } else {
            extra_refs_ += nl + nr - count;
            for (int side = 0; side < 2; ++side) {
                child_box[side] = child_cbox[side] = Bounds{};
                for (const PrimRef& r : side_refs[side]) {
                    child_box[side].grow(r.lo, r.hi);
                    child_cbox[side].grow_point(r.centroid2());
                }
            }
        }
    }
    if (leaf) {
        set_first_count(nodes[node], uint32_t(out_refs.size()), count);
        out_refs.insert(out_refs.end(), refs.begin(), refs.end());
        out_ids.insert(out_ids.end(), ids.begin(), ids.end());
        depth = std::max(depth, level);
        return;
    }
    if (!spatial) {
        const uint32_t larger = std::max(mid, count - mid);
        if (mid == 0 || mid == count || levels_needed(larger, max_leaf_) > budget)
            mid = partition_median(refs.data(), ids.data(), task, child_box, child_cbox);
        for (int side = 0; side < 2; ++side) {
            const uint32_t b = side == 0 ? 0 : mid, e = side == 0 ? mid : count;
            side_refs[side].assign(refs.begin() + b, refs.begin() + e);
            side_ids[side].assign(ids.begin() + b, ids.begin() + e);
        }
    }
    refs.clear(), refs.shrink_to_fit(), ids.clear(), ids.shrink_to_fit();
    const uint32_t left = uint32_t(nodes.size());
    set_first_count(nodes[node], left, 0);
    nodes.emplace_back();
    nodes.emplace_back();
    set_box(nodes[left], child_box[0]);
    set_box(nodes[left + 1], child_box[1]);
    for (int side = 0; side < 2; ++side)
        build_spatial_node(side_refs[side], side_ids[side], left + uint32_t(side), level + 1,
                           child_cbox[side], nodes, scratch, out_refs, out_ids, depth);
}

void Builder::build_spatial(const gpu::BvhNode& root_node, const Bounds& root_cbox,
                            std::vector<gpu::BvhNode>& nodes, int& depth) {
    root_area_ = node_box(root_node).area();
    nodes.push_back(root_node);
    std::vector<PrimRef> refs = std::move(refs_), out_refs;
    std::vector<uint32_t> ids = std::move(ids_), out_ids;
    Scratch scratch(bins_);
    build_spatial_node(refs, ids, 0, 1, root_cbox, nodes, scratch, out_refs, out_ids, depth);
    refs_ = std::move(out_refs);
    ids_ = std::move(out_ids);
}

Bvh Builder::build() {
    const auto start = std::chrono::steady_clock::now();
    Bvh bvh;
    const Bounds root_cbox = make_refs();
    const uint32_t n = uint32_t(refs_.size());

    gpu::BvhNode root_node{};
    Bounds root_box;
    for (const PrimRef& r : refs_) root_box.grow(r.lo, r.hi);
    // An empty scene: one empty leaf whose inverted, finite box no ray can enter.
    if (n == 0) root_box.lo = V4{kHuge, kHuge, kHuge, 0.0f}, root_box.hi = -root_box.lo;
    set_box(root_node, root_box);
    const Task root{0, n, 0, 1, root_cbox};

    const unsigned threads = std::min(8u, std::max(1u, std::thread::hardware_concurrency()));
    int depth = 0;
    if (split_budget_ > 0.0f && n > 0) {
        build_spatial(root_node, root_cbox, bvh.nodes, depth);
    } else if (threads > 1 && n >= kParallelMinTriangles) {
        bvh.nodes = build_parallel(root, root_node, threads, depth);
    } else {
        bvh.nodes.reserve(n > 0 ? 2 * size_t(n) - 1 : 1);  // a binary tree with n leaves at most
        bvh.nodes.push_back(root_node);
        Scratch scratch(bins_);
        build_subtree(root, bvh.nodes, scratch, 0, nullptr);
        depth = scratch.depth;
    }

    // Triangles in leaf order (a triangle split by spatial splits once per reference).
    const uint32_t references = uint32_t(ids_.size());
    bvh.triangles.resize(references);
    for (uint32_t i = 0; i < references; ++i) {
        const uint32_t t = ids_[i];
        const glm::vec3* p = &scene_.positions[3 * size_t(t)];
        gpu::Triangle& tri = bvh.triangles[i];
        tri.p0 = {p[0].x, p[0].y, p[0].z, 0.0f};
        tri.p1 = {p[1].x, p[1].y, p[1].z, 0.0f};
        tri.p2 = {p[2].x, p[2].y, p[2].z, 0.0f};
        tri.material = scene_.triangle_material[t];
        tri.index = t;
    }
    fill_stats(bvh, depth);

    // The device traverses the 4-wide collapse of this tree, its leaves in packets.
    const auto collapse_start = std::chrono::steady_clock::now();
    Bvh4 bvh4 = collapse_to_bvh4(bvh.nodes, traversal_cost_);
    bvh.nodes4 = std::move(bvh4.nodes);
    bvh.packets = pack_leaves(bvh.nodes4, bvh.triangles);
    bvh.stats.depth4 = bvh4.depth;
    bvh.stats.sah_cost4 = bvh4.sah_cost;
    bvh.stats.packets = bvh.packets.size();
    bvh.stats.references = bvh.triangles.size();
    bvh.stats.bytes = bvh.nodes4.size() * sizeof(gpu::Bvh4Node) +
                      bvh.packets.size() * (sizeof(gpu::TrianglePacket) +
                                            MCRT_PACKET_WIDTH * sizeof(gpu::TriangleInfo));
    const auto end = std::chrono::steady_clock::now();
    bvh.stats.collapse_seconds = std::chrono::duration<double>(end - collapse_start).count();
    bvh.stats.build_seconds = std::chrono::duration<double>(end - start).count();
    return bvh;
}

// SAH cost of the final tree: inner nodes cost traversal_cost, leaves their packets, weighted by
// A/A_root.
void Builder::fill_stats(Bvh& bvh, int depth) const {
    BvhStats& s = bvh.stats;
    const double root_area = node_box(bvh.nodes[0]).area();
    double cost = 0.0;
    for (const gpu::BvhNode& node : bvh.nodes) {
        const uint32_t count = gpu::as_uint(node.hi.w);
        // A flat root (a point or a segment) is entered by every ray that enters any node.
        const double ratio = root_area > 0.0 ? node_box(node).area() / root_area : 1.0;
        // Only the root of an empty scene is a leaf of count 0.
        if (count == 0 && bvh.nodes.size() > 1) {
            cost += traversal_cost_ * ratio;
            ++s.inner_nodes;
        } else {
            cost += packets_for(count) * ratio;
            ++s.leaves;
        }
    }
    s.sah_cost = cost;
    s.depth = depth;
}

}  // namespace

Bvh build_bvh(const Scene& scene, const BvhBuildOptions& options) {
    if (options.bins < 2 || options.bins > 1024)
        throw InputError("BVH build: bins must be in [2, 1024], got " +
                         std::to_string(options.bins));
    if (options.max_leaf_size < 1)
        throw InputError("BVH build: max_leaf_size must be at least 1, got " +
                         std::to_string(options.max_leaf_size));
    if (!(options.traversal_cost >= 0.0f))
        throw InputError("BVH build: traversal_cost must be non-negative");
    if (scene.positions.size() != 3 * scene.triangle_count())
        throw InputError("BVH build: scene has " + std::to_string(scene.positions.size()) +
                         " positions for " + std::to_string(scene.triangle_count()) + " triangles");
    if (scene.triangle_count() >= size_t(std::numeric_limits<uint32_t>::max()))
        throw InputError("BVH build: too many triangles for 32-bit indices");
    return Builder(scene, options).build();
}

}  // namespace mcrt
