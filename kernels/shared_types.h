/* Structs shared by the host (C++17) and the kernels (OpenCL C 1.2), declared once.
 * Only float, uint and float4 members; padding explicit; each size stated and checked by a
 * static_assert on the host and by the `shared_type_sizes` kernel on the device. */
#ifndef MCRT_SHARED_TYPES_H
#define MCRT_SHARED_TYPES_H

#ifndef __OPENCL_VERSION__
#include <cstdint>
namespace mcrt::gpu {
struct alignas(16) float4 {
    float x, y, z, w;
};
using uint = std::uint32_t;
#endif

/* Samples of one pixel are summed in chunks of this many consecutive sample indices, aligned
 * to multiples of it; batches start on chunk boundaries, so the floating-point sums, and the
 * image, do not depend on the batch size or the device split. */
#define MCRT_SAMPLES_PER_CHUNK 16

/* Longest root-to-leaf path of the binary BVH, in nodes (kMaxBvhDepth on the host): the builder
 * switches to median splits before a tree could grow deeper. */
#define MCRT_BVH_MAX_DEPTH 60

/* Binary BVH node of the host's SAH build, 32 bytes (the device traverses Bvh4Node). Children
 * of an inner node are adjacent: nodes[first], nodes[first+1].
 * lo.xyz / hi.xyz: bounds. lo.w: `first` (child or triangle index, as uint bits).
 * hi.w: triangle count as uint bits; 0 for an inner node. */
typedef struct {
    float4 lo;
    float4 hi;
} BvhNode;

/* 4-wide BVH node, 128 bytes: the boxes of its four children in SoA form, so that one slab test
 * in float4 arithmetic covers all four (Wald, Benthin, Boulos 2008, "Getting rid of packets";
 * Embree's BVH4). Slot i is
 *   - an inner child: count[i] == 0, child[i] = index of its Bvh4Node;
 *   - a leaf: count[i] = number of triangles (> 0), child[i] = index of its first
 *     TrianglePacket; the leaf's triangles fill packets child[i] .. child[i] + ceil(count/4) - 1
 *     lane by lane, in leaf order;
 *   - empty: count[i] == 0, child[i] == 0 and an inverted box (lo = +1e30, hi = -1e30) that the
 *     traversal's sign-selected slab test always rejects (near plane beyond far plane).
 * nodes[0] is the root; an empty scene's root has four empty slots. */
typedef struct {
    float4 lo_x, hi_x; /* 0, 16: order lo, hi per axis: the slab test picks near/far by index */
    float4 lo_y, hi_y; /* 32, 48 */
    float4 lo_z, hi_z; /* 64, 80 */
    uint child[4];     /* 96 */
    uint count[4];     /* 112 */
} Bvh4Node;

/* Up to four triangles of one leaf in SoA form, 160 bytes, so that one watertight test in float4
 * arithmetic covers all four (Wald, Benthin, Boulos 2008; Embree's triangle4). v[3k + a] holds
 * coordinate a (x, y, z) of vertex k of the four lanes; index[i] is lane i's triangle in leaf
 * order (the Triangle array), NO_HIT (0xffffffff) for an unused lane, whose vertices are 0. */
typedef struct {
    float4 v[9];    /* 0: x0, y0, z0, x1, y1, z1, x2, y2, z2 */
    uint index[4];  /* 144 */
} TrianglePacket;

/* Triangles per TrianglePacket: the SAH counts a leaf of N triangles as ceil(N / 4) tests. */
#define MCRT_PACKET_WIDTH 4

/* What shading needs of a hit triangle besides its vertices (which it reads from the packet),
 * 8 bytes, one per packet lane: info[4 · packet + lane]; unused lanes hold zeros. */
typedef struct {
    uint material; /* index into the materials */
    uint light;    /* index of its Light plus one, 0 when it is not a light */
} TriangleInfo;

/* Longest root-to-leaf path of Bvh4Node (counting inner Bvh4Nodes): every Bvh4Node is an inner
 * node of the binary tree, so at most MCRT_BVH_MAX_DEPTH - 1 of them lie on a path. */
#define MCRT_BVH4_MAX_DEPTH (MCRT_BVH_MAX_DEPTH - 1)

/* Triangle in BVH leaf order, 48 bytes, on the host (Bvh::triangles; the device reads vertices
 * from TrianglePacket and the rest from TriangleInfo): world-space vertices, counter-clockwise
 * seen from the front. p0.w holds the material index as uint bits; p1.w the scene's triangle
 * index; p2.w is 0. */
typedef struct {
    float4 p0;
    float4 p1;
    float4 p2;
} Triangle;

#define MATERIAL_DOUBLE_SIDED 1u

/* Lambertian material that may emit, 48 bytes. */
typedef struct {
    float4 albedo; /* .xyz reflectance, .w unused */
    float4 Le;     /* .xyz emitted radiance, .w unused */
    uint flags;    /* MATERIAL_DOUBLE_SIDED */
    uint pad0, pad1, pad2;
} Material;

/* Emissive triangle for light sampling, 64 bytes. */
typedef struct {
    float4 p0;  /* .w area */
    float4 p1;  /* .w uint bits: flags (MATERIAL_DOUBLE_SIDED) */
    float4 p2;  /* .w unused */
    float4 Le;  /* .xyz emitted radiance, .w unused (selection pmfs live in the light CDF) */
} Light;

/* One entry of an alias table (Walker 1977; Vose 1991), 16 bytes, on the 2^-24 grid of the
 * kernels' u (kernels/discrete.cl): bucket i keeps i when its coin, an integer in [0, 2^24), is
 * below threshold, else gives alias; pmf is the probability of i itself, exactly (a whole
 * number of 2^-24 steps, as the host counts them). */
typedef struct {
    uint threshold;
    uint alias;
    float pmf;
    uint pad0;
} AliasEntry;

/* Pinhole camera, 64 bytes. A ray through film point (x, y) in [-1, 1]² (x right, y up) has
 * direction forward + x·right + y·up, where right and up are already scaled by
 * tan(yfov/2)·aspect and tan(yfov/2) (DESIGN.md "Camera contract"). */
typedef struct {
    float4 eye;
    float4 right;
    float4 up;
    float4 forward;
} CameraGpu;

#ifndef __OPENCL_VERSION__
static_assert(sizeof(BvhNode) == 32 && alignof(BvhNode) == 16, "BvhNode layout");
static_assert(sizeof(Bvh4Node) == 128 && alignof(Bvh4Node) == 16, "Bvh4Node layout");
static_assert(sizeof(TrianglePacket) == 160 && alignof(TrianglePacket) == 16, "TrianglePacket layout");
static_assert(sizeof(TriangleInfo) == 8 && alignof(TriangleInfo) == 4, "TriangleInfo layout");
static_assert(sizeof(Triangle) == 48 && alignof(Triangle) == 16, "Triangle layout");
static_assert(sizeof(Material) == 48 && alignof(Material) == 16, "Material layout");
static_assert(sizeof(Light) == 64 && alignof(Light) == 16, "Light layout");
static_assert(sizeof(AliasEntry) == 16 && alignof(AliasEntry) == 4, "AliasEntry layout");
static_assert(sizeof(CameraGpu) == 64 && alignof(CameraGpu) == 16, "CameraGpu layout");
}  // namespace mcrt::gpu
#endif

#endif /* MCRT_SHARED_TYPES_H */
