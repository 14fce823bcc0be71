/* Structs shared by the host (C++17) and the kernels (OpenCL C 1.2), declared once.
 * Only float, uint and float4 members; padding explicit; each size, alignment and offset listed
 * once in MCRT_SHARED_LAYOUT (at the end), checked by static_assert on the host and by the
 * `shared_type_layout` kernel on the device. */
#ifndef MCRT_SHARED_TYPES_H
#define MCRT_SHARED_TYPES_H

#ifdef __OPENCL_VERSION__
/* No a·b + c fused into one rounding anywhere: every device then rounds each operation alike,
 * and an image is the same bits whichever device renders it (docs/DESIGN.md, "Determinism"). It
 * holds to the end of each program, user estimator files included. */
#pragma OPENCL FP_CONTRACT OFF
/* Intel's CPU runtime (2026.2; the host defines MCRT_INTEL_CPU there) vectorises a kernel across
 * work-items, and its vectoriser returns wrong values from any function it does not inline that
 * returns a float3 (four lines show it: docs/ROBUSTNESS.md). With -D MCRT_INTEL_VECTORIZE
 * (MCRT_KERNEL_OPTIONS) every function declared `inline` is inlined, and the vectorised kernels
 * render PoCL's bits; but slower than the unvectorised kernels on every variant measured
 * (docs/BENCHMARKS.md, "Intel's OpenCL CPU runtime beside PoCL"): each lane
 * fetches its own float4 nodes and triangle packets by gathers. So by default each work-item
 * runs as scalar code there, as on PoCL. render.cl includes this header before any function. */
#if defined(MCRT_INTEL_CPU) && defined(MCRT_INTEL_VECTORIZE)
#define inline inline __attribute__((always_inline))
#elif defined(MCRT_INTEL_CPU)
#define kernel __kernel __attribute__((intel_vec_len_hint(1)))
#endif
#include "arithmetic.cl"

#endif

#ifndef __OPENCL_VERSION__
#include <cstddef>
#include <cstdint>
#include <cstring>
namespace mcrt::gpu {
struct alignas(16) float4 {
    float x, y, z, w;
};
using uint = std::uint32_t;

/* The kernels' as_float / as_uint on the host: uint bits stored in a float member and back. */
inline float as_float(uint u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}
inline uint as_uint(float f) {
    uint u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}
#endif

/* A triangle or packet-lane index that names nothing: a ray's miss, an unused packet lane. */
#define MCRT_NO_HIT 0xffffffffu

/* 1/π, for the Lambertian f_r = albedo/π and cosine densities. */
#define MCRT_INV_PI 0.318309886183790671538f

/* Samples of one pixel are summed in chunks of this many consecutive sample indices, aligned
 * to multiples of it; batches start on chunk boundaries, so the floating-point sums, and the
 * image, do not depend on the batch size or the device split. */
#define MCRT_SAMPLES_PER_CHUNK 16

/* The longest light path, in reflections (--max-depth): the host's option check, the per-vertex
 * random-number dimensions (rng.cl) and the packed path statistics (path.cl) agree on it. */
#define MCRT_MAX_PATH_DEPTH 1024u

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
 * coordinate a (x, y, z) of vertex k of the four lanes; index[i] is lane i's triangle in the
 * scene's (glTF) order, which the closest hit's ties follow whatever the tree, MCRT_NO_HIT for an
 * unused lane, whose vertices are 0. In the device scene (host/render/gpu_scene.cpp) a lane's
 * index also carries MCRT_TRIANGLE_CULLED. */
typedef struct {
    float4 v[9];    /* 0: x0, y0, z0, x1, y1, z1, x2, y2, z2 */
    uint index[4];  /* 144 */
} TrianglePacket;

/* Set in a used lane's TrianglePacket.index: the triangle is single-sided (glTF `doubleSided`
 * false) and not transmissive, so that no ray hits its back face (glTF 2.0 sec. 3.9.2; DESIGN.md
 * "Radiometric contract"). Only kernels built with -D MCRT_SINGLE_SIDED, for a scene that has
 * such a triangle, read it; the index proper is the other 31 bits. */
#define MCRT_TRIANGLE_CULLED 0x80000000u
#define MCRT_TRIANGLE_INDEX_MASK 0x7fffffffu

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

/* Triangle in BVH leaf order, 64 bytes, on the host (Bvh::triangles; the device reads vertices
 * from TrianglePacket and the rest from TriangleInfo): world-space vertices, counter-clockwise
 * seen from the front. */
typedef struct {
    float4 p0, p1, p2; /* .w 0 */
    uint material;     /* index into the materials */
    uint index;        /* the scene's index of the triangle */
    uint pad0, pad1;
} Triangle;

#define MATERIAL_DOUBLE_SIDED 1u
/* Some texture slot is used: shading evaluates the material's textures at the hit (-D
 * MCRT_TEXTURES builds only, MaterialTextures). On a Light: its emission varies over it. */
#define MATERIAL_TEXTURED 2u
/* alphaMode MASK or BLEND: every ray query tests the surface's alpha at a candidate hit. */
#define MATERIAL_ALPHA_TESTED 4u
/* KHR_materials_volume with thicknessFactor > 0 on a transmissive material: the surface bounds a
 * volume (its outside the front face); rays refract and are attenuated inside (bsdf.cl, path.cl).
 * Without it a transmissive surface is thin-walled. */
#define MATERIAL_VOLUME 8u

/* Material.type: the reflection model of a surface. The kernels' build follows the scene
 * (DESIGN.md "Radiometric contract": model no more than a scene needs): a scene whose every
 * material is MATERIAL_LAMBERTIAN gets the course's Lambertian kernels; one with any other type
 * the kernels of that model (-D MCRT_MATERIALS_GLTF), which evaluate a Lambertian material as
 * the metallic-roughness BRDF with metallic 0 and F0 = F90 = 0, the same reflection. */
#define MATERIAL_LAMBERTIAN 0u
#define MATERIAL_METALLIC_ROUGHNESS 1u

/* A surface's material, 96 bytes: glTF 2.0 metallic-roughness that may emit and transmit
 * (DESIGN.md "Radiometric contract"). */
typedef struct {
    float4 base_color; /* .xyz baseColorFactor, linear; .w its alpha */
    float4 emission;   /* .xyz emitted radiance (emissiveFactor × emissive_strength); .w 0 */
    float4 specular;   /* the dielectric's Schlick pair (KHR_materials_specular, _ior): .xyz F0 =
                          min(f0(ior) specularColorFactor, 1) × specularFactor, .w F90 =
                          specularFactor */
    float metallic;    /* metallicFactor */
    float alpha;       /* GGX α = max(roughness², MCRT_ALPHA_MIN) */
    uint type;         /* MATERIAL_LAMBERTIAN or MATERIAL_METALLIC_ROUGHNESS */
    uint flags;        /* MATERIAL_DOUBLE_SIDED, MATERIAL_VOLUME, ... */
    float4 attenuation; /* MATERIAL_VOLUME: .xyz Beer–Lambert attenuation per unit length in bits,
                           −log2(attenuationColor)/attenuationDistance (0: none); .w 0 */
    float transmission; /* KHR_materials_transmission.transmissionFactor; 0: opaque */
    float ior;          /* KHR_materials_ior.ior (≥ 1, or 0: the Fresnel term is 1) */
    uint pad0, pad1;
} Material;

/* The least GGX α: roughness 0 (a mirror, a delta the estimators cannot sample) is read as
 * α = 10⁻³, roughness ≈ 0.032, whose lobe is a few milliradians wide (pbrt-v4 treats α below
 * 10⁻³ as smooth). */
#define MCRT_ALPHA_MIN 1.0e-3f

/* Emissive triangle for light sampling, 80 bytes. What a light selection knows of the lights
 * beside their power (its CDF, alias table or tree) lives in that selection's own buffer. */
typedef struct {
    float4 p0, p1, p2; /* vertices, counter-clockwise seen from the front; .w 0 */
    float4 Le;         /* .xyz emitted radiance (the factor; × its texture where MATERIAL_TEXTURED);
                          .w 0 */
    float area;
    uint flags;        /* MATERIAL_DOUBLE_SIDED, MATERIAL_TEXTURED (emission varies over it, or
                          alpha cuts it: evaluated at the sampled point) */
    uint material;     /* index into the materials */
    uint surface;      /* its triangle's packet lane (TriangleSurface, TriangleInfo) */
} Light;

/* PunctualGpu.type: a KHR_lights_punctual light (DESIGN.md "Punctual lights"). */
#define PUNCTUAL_POINT 0u
#define PUNCTUAL_SPOT 1u
#define PUNCTUAL_DIRECTIONAL 2u

/* A punctual light (-D MCRT_PUNCTUAL builds), 64 bytes: a delta light, which the light
 * selections choose beside the light_count area lights as light light_count + i (its power or
 * tree slot in the selection's data) and which no ray can hit. */
typedef struct {
    float4 position;    /* .xyz world (point, spot); .w 0 */
    float4 direction;   /* .xyz unit, where the light points (spot, directional); .w 0 */
    float4 intensity;   /* .xyz color × intensity: radiant intensity (point, spot) or irradiance
                           (directional); .w 0 */
    float spot_scale;   /* spot falloff clamp(cos θ · scale + offset, 0, 1)²; point: 0, 1 */
    float spot_offset;
    uint type;          /* PUNCTUAL_* */
    uint pad0;
} PunctualGpu;

/* Node of the light tree (host/render/light_tree.h), 208 bytes: four slots, each a child node
 * or one light, with the bounds of the lights below it for the importance of
 * kernels/lights/light_tree.cl (Conty Estevez & Kulla 2018; pbrt-v4's LightBounds), laid out as one
 * float4 per quantity so that the four importances are one vector computation. nodes[0] is the
 * root. Per slot k (the vectors' component k):
 * x, y, z: centre of the box of the lights' vertices; radius: of the box's bounding sphere about
 * it, rounded up. ax, ay, az: unit axis w of the cone of emitting normals; cos_o: cos θ_o, its
 * half-angle, rounded down, sin_o its sine rounded up; cos_e: cos θ_e, how far beyond the normals
 * a light emits (π/2 for area lights: 0), rounded down. phi: power φ, 0 for an empty slot.
 * child[k]: the child node's index, or the light's where bit k of flags is set
 * (LIGHT_SLOT_LEAF << k); LIGHT_SLOT_TWO_SIDED << k: some light below emits both ways. */
typedef struct {
    float4 x, y, z;
    float4 radius;
    float4 ax, ay, az;
    float4 cos_o;
    float4 sin_o;
    float4 cos_e;
    float4 phi;
    uint child[4];
    uint flags;
    uint pad0, pad1, pad2;
} LightTreeNode;

#define LIGHT_TREE_WIDTH 4
#define LIGHT_SLOT_LEAF 1u        /* << slot */
#define LIGHT_SLOT_TWO_SIDED 16u  /* << slot */

/* Longest root-to-leaf path of the light tree, in levels of nodes: a light's path is a trail of
 * two bits per level (LightTreePath), the builder switching to median splits before a path
 * could grow longer. */
#define MCRT_LIGHT_TREE_MAX_DEPTH 16

/* A light's path from the light tree's root to its slot, 8 bytes, one per light after the
 * tree's nodes in the tree's buffer: bits 2d, 2d + 1 of `bits` the slot taken at depth d;
 * `length` its number of nodes, 0 for a light not in the tree (no power).
 * The twins of the tree's choice (light_tree_pmf) walk it. */
typedef struct {
    uint bits;
    uint length;
} LightTreePath;

/* One entry of an alias table (Walker 1977; Vose 1991), 16 bytes, on the 2^-24 grid of the
 * kernels' u (kernels/sampling/discrete.cl): bucket i keeps i when its coin, an integer in
 * [0, 2^24), is below threshold, else gives alias; pmf is the probability of i itself, exactly
 * (a whole number of 2^-24 steps, as the host counts them). */
typedef struct {
    uint threshold;
    uint alias;
    float pmf;
    uint pad0;
} AliasEntry;

/* ---- Textures (-D MCRT_TEXTURES builds; docs/MATERIALS.md "Textures") ---------------------- */

/* TextureSlot.image of an empty slot. */
#define MCRT_NO_TEXTURE 0xffffffffu

/* TextureSlot.mode: the wrap mode of each axis (glTF 2.0 "Samplers"), in 2 bits each at
 * TEXTURE_WRAP_S_SHIFT and TEXTURE_WRAP_T_SHIFT, the magnification filter, the transfer
 * function and the texture-coordinate set. */
#define TEXTURE_WRAP_REPEAT 0u
#define TEXTURE_WRAP_CLAMP 1u
#define TEXTURE_WRAP_MIRROR 2u
#define TEXTURE_WRAP_S_SHIFT 0u
#define TEXTURE_WRAP_T_SHIFT 2u
#define TEXTURE_LINEAR 16u    /* bilinear; else nearest */
#define TEXTURE_SRGB 32u      /* colour channels sRGB-encoded (baseColor, emissive) */
#define TEXTURE_TEXCOORD_1 64u /* reads TEXCOORD_1; else TEXCOORD_0 */

/* A material's texture in one slot, 32 bytes: KHR_texture_transform's 2×3 matrix
 * (u' = m.x·u + m.y·v + offset_u, v' = m.z·u + m.w·v + offset_v) and how it is read. */
typedef struct {
    float4 m;
    float offset_u, offset_v;
    uint image;  /* index of its TextureImageGpu; MCRT_NO_TEXTURE: empty */
    uint mode;   /* TEXTURE_* */
} TextureSlot;

/* MaterialTextures.alpha_mode (glTF 2.0 alphaMode). */
#define MATERIAL_ALPHA_OPAQUE 0u
#define MATERIAL_ALPHA_MASK 1u
#define MATERIAL_ALPHA_BLEND 2u

/* The textures and alpha of one material, 192 bytes, parallel to the materials. */
typedef struct {
    TextureSlot base_color;         /* sRGB: RGB × base_color, A × its alpha */
    TextureSlot metallic_roughness; /* linear: B × metallic, G × roughness */
    TextureSlot normal;             /* linear: tangent-space normal */
    TextureSlot emissive;           /* sRGB: RGB × emission */
    float base_alpha;   /* baseColorFactor.a */
    float alpha_cutoff; /* MASK: cut where alpha < alpha_cutoff */
    float normal_scale; /* normalTexture.scale */
    uint alpha_mode;    /* MATERIAL_ALPHA_* */
    float roughness;    /* roughnessFactor (Material.alpha is its square, clamped) */
    /* The normal texture's KHR_texture_transform rotation (cos, sin): the tangent frame follows
     * the untransformed coordinates, so the texel's x and y are turned back by it. */
    float normal_cos, normal_sin;
    uint pad0;
    TextureSlot transmission; /* linear: R × transmission (KHR_materials_transmission) */
} MaterialTextures;

/* One image of the texel data, 16 bytes: its texels, row by row from the top, one RGBA8 texel
 * per 32-bit word (red in the low byte). */
typedef struct {
    uint offset;  /* first texel, in words from the start of the texels */
    uint width, height;
    uint pad0;
} TextureImageGpu;

/* Head of the texture data (RENDER_ARG_TEXTURES), 16 bytes, followed by the materials'
 * MaterialTextures; each offset in 32-bit words from the start of the data. */
typedef struct {
    uint materials; /* count of MaterialTextures after the head */
    uint images;    /* the TextureImageGpu table */
    uint decode;    /* 512 floats: 8-bit value → linear for sRGB (256), then for linear (256) */
    uint texels;
} TextureHeader;

/* What texture lookups need of a triangle besides its vertices, 144 bytes, one per packet lane as
 * TriangleInfo (zeros for unused lanes), for the corners in the order of its vertices. */
typedef struct {
    float4 uv[3];      /* .xy TEXCOORD_0, .zw TEXCOORD_1 */
    float4 normal[3];  /* .xyz unit vertex normal (normal-textured materials only); .w 0 */
    float4 tangent[3]; /* .xyz unit tangent, .w handedness ±1 (bitangent w·n×t) */
} TriangleSurface;

/* Pinhole camera, 64 bytes. A ray through film point (x, y) in [-1, 1]² (x right, y up) has
 * direction forward + x·right + y·up, where right and up are already scaled by
 * tan(yfov/2)·aspect and tan(yfov/2) (DESIGN.md "Camera contract"). */
typedef struct {
    float4 eye;
    float4 right;
    float4 up;
    float4 forward;
} CameraGpu;

/* The per-render values of the render kernel, passed by value as its last argument, 96 bytes.
 * Values that change per render or per launch live here, never in -D options, so they never
 * trigger a rebuild: a sweep over them reuses one program. */
typedef struct {
    float4 sky;         /* .xyz uniform sky radiance (ambient estimators, or the sky light);
                           .w the probability that the light strategies choose the sky light,
                           0 when the sky is no light (light_sampling.cl) */
    float ao_distance;  /* ambient occlusion range; 0 = unbounded */
    uint width, height; /* image size in pixels */
    uint seed;
    uint spp;           /* samples per pixel of the whole render (strata, spiral points) */
    uint light_count;   /* area lights (emissive triangles) */
    uint pixel_begin, pixel_end; /* this launch: pixels [pixel_begin, pixel_end) */
    uint sample_begin;  /* this launch: samples [sample_begin, sample_begin + batch_samples) */
    uint batch_samples; /*   of each pixel */
    uint replicates;    /* K independent randomizations of the sampler: sample s belongs to
                           replicate s % K as its sample s / K of spp / K (K divides 16 and spp) */
    uint max_depth;     /* reflections a path may have (--max-depth); 1: direct lighting */
    uint rr_depth;      /* Russian roulette before reflection k >= rr_depth (--rr-depth) */
    uint light_tree_nodes; /* the light tree's nodes at the head of the selection's buffer */
    uint env_width, env_height; /* the environment map's texels (-D MCRT_ENVIRONMENT_MAP builds;
                                   sky.w is then the probability of choosing it) */
    float env_cos_rot, env_sin_rot; /* its turn about +Y (--env-rotate) */
    uint punctual_count;   /* punctual lights (RENDER_ARG_PUNCTUAL), chosen after the
                              light_count area lights (-D MCRT_PUNCTUAL builds); 0 otherwise */
    uint pad1;
} RenderParams;

/* What reduce_chunks writes for one run of samples: the samples of one pixel, one chunk and one
 * replicate, 64 bytes. The sums are shifted by the run's first value and scaled by a power of
 * two per channel (2^-e, 2^e the largest magnitude in the run), so that a run of equal values
 * sums to exactly zero spread and no square overflows, up to float's range (Chan, Golub &
 * LeVeque 1983 on shifted sums). Non-finite samples are counted and read as 0. */
typedef struct {
    float4 shift;    /* .xyz the run's first sample, .w non-finite samples in the run */
    float4 sum;      /* .xyz Σ (x·2^-e − shift·2^-e), .w rays traced */
    float4 sum_sq;   /* .xyz Σ (x·2^-e − shift·2^-e)², .w samples in the run */
    float4 exponent; /* .xyz e, whole numbers; .w path vertices of the run's samples
                        + 2^15 × those of its paths that roulette ended (a whole number:
                        16 × (MCRT_MAX_PATH_DEPTH + 1) vertices fit below 2^15) */
} ChunkSums;

/* The render kernel's arguments in order (kernels/render/render.cl); the host binds them all in one
 * place (bind_render_arguments, host/render/device_worker.cpp). */
enum RenderArgument {
    RENDER_ARG_NODES,           /* global const Bvh4Node* */
    RENDER_ARG_PACKETS,         /* global const TrianglePacket* */
    RENDER_ARG_TRIANGLE_INFO,   /* global const TriangleInfo*: per packet lane */
    RENDER_ARG_MATERIALS,       /* global const Material* */
    RENDER_ARG_LIGHTS,          /* global const Light* */
    RENDER_ARG_LIGHT_SELECTION, /* global const uint*: the light selection's own data, built
                                   only for it (kernels/lights/lights.cl, light_set): power's CDF
                                   (light_count + 1 floats), alias's table (light_count
                                   AliasEntry), the tree's nodes (light_tree_nodes
                                   LightTreeNode) followed by the lights' LightTreePath;
                                   uniform reads none */
    RENDER_ARG_SURFACES,        /* global const TriangleSurface*: per packet lane (textured
                                   builds; a placeholder otherwise) */
    RENDER_ARG_TEXTURES,        /* global const uint*: TextureHeader, MaterialTextures, images,
                                   decode tables, texels (textured builds; else a placeholder) */
    RENDER_ARG_ENVIRONMENT,     /* global const float*: the environment map's RGB texels (3 per
                                   texel, row 0 at the zenith) followed by its texel CDF
                                   (env_width·env_height + 1 entries) (-D MCRT_ENVIRONMENT_MAP
                                   builds; a placeholder otherwise) */
    RENDER_ARG_PUNCTUAL,        /* global const PunctualGpu*: the punctual lights (-D
                                   MCRT_PUNCTUAL builds; a placeholder otherwise) */
    RENDER_ARG_CAMERA,          /* global const CameraGpu* */
    RENDER_ARG_SAMPLES,         /* global uint4*: out, one per work-item (the radiance's bits,
                                   the packed PathRecord) */
    RENDER_ARG_PARAMS,          /* RenderParams, by value */
    RENDER_ARG_COUNT
};

/* Size, alignment and field offsets of every shared struct, listed once: the host checks them
 * with static_assert (below), the device reports its own through the `shared_type_layout`
 * kernel (kernels/render/render.cl) and a test compares the two. TYPE(T, size, align) opens a
 * struct, FIELD(T, member, offset) follows for each member. */
#define MCRT_SHARED_LAYOUT(TYPE, FIELD)                                                          \
    TYPE(BvhNode, 32, 16) FIELD(BvhNode, lo, 0) FIELD(BvhNode, hi, 16)                          \
    TYPE(Bvh4Node, 128, 16) FIELD(Bvh4Node, lo_x, 0) FIELD(Bvh4Node, hi_x, 16)                  \
    FIELD(Bvh4Node, lo_y, 32) FIELD(Bvh4Node, hi_y, 48) FIELD(Bvh4Node, lo_z, 64)               \
    FIELD(Bvh4Node, hi_z, 80) FIELD(Bvh4Node, child, 96) FIELD(Bvh4Node, count, 112)            \
    TYPE(TrianglePacket, 160, 16) FIELD(TrianglePacket, v, 0) FIELD(TrianglePacket, index, 144) \
    TYPE(TriangleInfo, 8, 4) FIELD(TriangleInfo, material, 0) FIELD(TriangleInfo, light, 4)     \
    TYPE(Triangle, 64, 16) FIELD(Triangle, p0, 0) FIELD(Triangle, p1, 16)                       \
    FIELD(Triangle, p2, 32) FIELD(Triangle, material, 48) FIELD(Triangle, index, 52)            \
    TYPE(Material, 96, 16) FIELD(Material, base_color, 0) FIELD(Material, emission, 16)         \
    FIELD(Material, specular, 32) FIELD(Material, metallic, 48) FIELD(Material, alpha, 52)      \
    FIELD(Material, type, 56) FIELD(Material, flags, 60) FIELD(Material, attenuation, 64)       \
    FIELD(Material, transmission, 80) FIELD(Material, ior, 84)                                  \
    TYPE(Light, 80, 16) FIELD(Light, p0, 0) FIELD(Light, p1, 16) FIELD(Light, p2, 32)           \
    FIELD(Light, Le, 48) FIELD(Light, area, 64) FIELD(Light, flags, 68)                         \
    FIELD(Light, material, 72) FIELD(Light, surface, 76)                                        \
    TYPE(TextureSlot, 32, 16) FIELD(TextureSlot, m, 0) FIELD(TextureSlot, offset_u, 16)         \
    FIELD(TextureSlot, offset_v, 20) FIELD(TextureSlot, image, 24) FIELD(TextureSlot, mode, 28) \
    TYPE(MaterialTextures, 192, 16) FIELD(MaterialTextures, base_color, 0)                      \
    FIELD(MaterialTextures, metallic_roughness, 32) FIELD(MaterialTextures, normal, 64)         \
    FIELD(MaterialTextures, emissive, 96) FIELD(MaterialTextures, base_alpha, 128)              \
    FIELD(MaterialTextures, alpha_cutoff, 132) FIELD(MaterialTextures, normal_scale, 136)       \
    FIELD(MaterialTextures, alpha_mode, 140) FIELD(MaterialTextures, roughness, 144)            \
    FIELD(MaterialTextures, normal_cos, 148) FIELD(MaterialTextures, normal_sin, 152)           \
    FIELD(MaterialTextures, transmission, 160)                                                  \
    TYPE(TextureImageGpu, 16, 4) FIELD(TextureImageGpu, offset, 0)                              \
    FIELD(TextureImageGpu, width, 4) FIELD(TextureImageGpu, height, 8)                          \
    TYPE(TextureHeader, 16, 4) FIELD(TextureHeader, materials, 0)                               \
    FIELD(TextureHeader, images, 4) FIELD(TextureHeader, decode, 8)                             \
    FIELD(TextureHeader, texels, 12)                                                            \
    TYPE(TriangleSurface, 144, 16) FIELD(TriangleSurface, uv, 0)                                \
    FIELD(TriangleSurface, normal, 48) FIELD(TriangleSurface, tangent, 96)                      \
    TYPE(PunctualGpu, 64, 16) FIELD(PunctualGpu, position, 0)                                   \
    FIELD(PunctualGpu, direction, 16) FIELD(PunctualGpu, intensity, 32)                         \
    FIELD(PunctualGpu, spot_scale, 48) FIELD(PunctualGpu, spot_offset, 52)                      \
    FIELD(PunctualGpu, type, 56)                                                                \
    TYPE(LightTreePath, 8, 4) FIELD(LightTreePath, bits, 0) FIELD(LightTreePath, length, 4)     \
    TYPE(AliasEntry, 16, 4) FIELD(AliasEntry, threshold, 0) FIELD(AliasEntry, alias, 4)         \
    FIELD(AliasEntry, pmf, 8)                                                                   \
    TYPE(LightTreeNode, 208, 16) FIELD(LightTreeNode, x, 0) FIELD(LightTreeNode, y, 16)       \
    FIELD(LightTreeNode, z, 32) FIELD(LightTreeNode, radius, 48) FIELD(LightTreeNode, ax, 64)   \
    FIELD(LightTreeNode, ay, 80) FIELD(LightTreeNode, az, 96) FIELD(LightTreeNode, cos_o, 112)  \
    FIELD(LightTreeNode, sin_o, 128) FIELD(LightTreeNode, cos_e, 144)                           \
    FIELD(LightTreeNode, phi, 160) FIELD(LightTreeNode, child, 176)                             \
    FIELD(LightTreeNode, flags, 192)                                                            \
    TYPE(CameraGpu, 64, 16) FIELD(CameraGpu, eye, 0) FIELD(CameraGpu, right, 16)                \
    FIELD(CameraGpu, up, 32) FIELD(CameraGpu, forward, 48)                                      \
    TYPE(RenderParams, 96, 16) FIELD(RenderParams, sky, 0) FIELD(RenderParams, ao_distance, 16) \
    FIELD(RenderParams, width, 20) FIELD(RenderParams, height, 24) FIELD(RenderParams, seed, 28) \
    FIELD(RenderParams, spp, 32) FIELD(RenderParams, light_count, 36)                           \
    FIELD(RenderParams, pixel_begin, 40) FIELD(RenderParams, pixel_end, 44)                     \
    FIELD(RenderParams, sample_begin, 48) FIELD(RenderParams, batch_samples, 52)                 \
    FIELD(RenderParams, replicates, 56) FIELD(RenderParams, max_depth, 60)                      \
    FIELD(RenderParams, rr_depth, 64) FIELD(RenderParams, light_tree_nodes, 68)                 \
    FIELD(RenderParams, env_width, 72) FIELD(RenderParams, env_height, 76)                      \
    FIELD(RenderParams, env_cos_rot, 80) FIELD(RenderParams, env_sin_rot, 84)                   \
    FIELD(RenderParams, punctual_count, 88)                                                     \
    TYPE(ChunkSums, 64, 16) FIELD(ChunkSums, shift, 0) FIELD(ChunkSums, sum, 16)                \
    FIELD(ChunkSums, sum_sq, 32) FIELD(ChunkSums, exponent, 48)

#ifndef __OPENCL_VERSION__
#define MCRT_CHECK_TYPE(T, size, align) \
    static_assert(sizeof(T) == size && alignof(T) == align, #T " size or alignment");
#define MCRT_CHECK_FIELD(T, member, offset) \
    static_assert(offsetof(T, member) == offset, #T "." #member " offset");
MCRT_SHARED_LAYOUT(MCRT_CHECK_TYPE, MCRT_CHECK_FIELD)
#undef MCRT_CHECK_TYPE
#undef MCRT_CHECK_FIELD
}  // namespace mcrt::gpu
#endif

#endif /* MCRT_SHARED_TYPES_H */
