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
          traversal_cost_(options.traversal_cost) {}

    Bvh build();

  private:
    Bounds make_refs();
    void build_subtree(Task root, std::vector<gpu::BvhNode>& nodes, Scratch& scratch,
                       uint32_t defer_at_most, std::vector<Task>* deferred);
    std::vector<gpu::BvhNode> build_parallel(const Task& root, const gpu::BvhNode& root_node,
                                             unsigned threads, int& depth);
    SahSplit find_sah_split(const Task& task, Scratch& scratch);
    uint32_t partition_sah(const Task& task, const SahSplit& split, Bounds child_box[2],
                           Bounds child_cbox[2]);
    uint32_t partition_median(const Task& task, Bounds child_box[2], Bounds child_cbox[2]);
    void fill_stats(Bvh& bvh, int depth) const;

    const Scene& scene_;
    int bins_;
    uint32_t max_leaf_;
    float traversal_cost_;
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
SahSplit Builder::find_sah_split(const Task& task, Scratch& scratch) {
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
        const PrimRef& r = refs_[i];
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
uint32_t Builder::partition_sah(const Task& task, const SahSplit& split, Bounds child_box[2],
                                Bounds child_cbox[2]) {
    const int k = split.axis;
    const V4 last_bin = V4{} + float(bins_ - 1);
    auto is_left = [&](const PrimRef& r) {
        return bins_of(r.centroid2(), task.cbox.lo, split.scale, last_bin)[k] <= split.bin;
    };
    auto add = [&](uint32_t i, int side) {
        child_box[side].grow(refs_[i].lo, refs_[i].hi);
        child_cbox[side].grow_point(refs_[i].centroid2());
    };
    uint32_t i = task.begin, j = task.end;
    for (;;) {
        while (i < j && is_left(refs_[i])) add(i++, 0);
        while (i < j && !is_left(refs_[j - 1])) add(--j, 1);
        if (i >= j) break;
        std::swap(refs_[i], refs_[j - 1]);
        std::swap(ids_[i], ids_[j - 1]);
        add(i++, 0);
        add(--j, 1);
    }
    return i;
}

// Splits refs[begin, end) at the middle index, ordered along the widest centroid axis (object
// median).
uint32_t Builder::partition_median(const Task& task, Bounds child_box[2], Bounds child_cbox[2]) {
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
                             return refs_[a].centroid2()[k] < refs_[b].centroid2()[k];
                         });
        std::vector<PrimRef> refs(order.size());
        std::vector<uint32_t> ids(order.size());
        for (size_t i = 0; i < order.size(); ++i)
            refs[i] = refs_[order[i]], ids[i] = ids_[order[i]];
        std::copy(refs.begin(), refs.end(), refs_.begin() + task.begin);
        std::copy(ids.begin(), ids.end(), ids_.begin() + task.begin);
    }
    for (int side = 0; side < 2; ++side) child_box[side] = child_cbox[side] = Bounds{};
    for (uint32_t i = task.begin; i < task.end; ++i) {
        const int side = i < mid ? 0 : 1;
        child_box[side].grow(refs_[i].lo, refs_[i].hi);
        child_cbox[side].grow_point(refs_[i].centroid2());
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
            split = find_sah_split(task, scratch);
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
        if (split.axis >= 0) mid = partition_sah(task, split, child_box, child_cbox);
        // Coincident centroids, or an SAH split too lopsided for the depth left: median split.
        const uint32_t larger = std::max(mid - task.begin, task.end - mid);
        if (mid == task.begin || mid == task.end || levels_needed(larger, max_leaf_) > budget)
            mid = partition_median(task, child_box, child_cbox);

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
    if (threads > 1 && n >= kParallelMinTriangles) {
        bvh.nodes = build_parallel(root, root_node, threads, depth);
    } else {
        bvh.nodes.reserve(n > 0 ? 2 * size_t(n) - 1 : 1);  // a binary tree with n leaves at most
        bvh.nodes.push_back(root_node);
        Scratch scratch(bins_);
        build_subtree(root, bvh.nodes, scratch, 0, nullptr);
        depth = scratch.depth;
    }

    // Triangles in leaf order.
    bvh.triangles.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
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
