/* Test entry points for the sampling routines (tests/sampling/test_sampling.cpp): each runs one family
 * of routines on given or hashed u values and writes what they return. Global sizes are 1D;
 * each entry checks its bound. */
#include "shared_types.h"
#include "discrete.cl"
#include "frame.cl"
#include "light_tree.cl"
#include "rng.cl"
#include "sampling.cl"

/* Kinds of direction sampler, the tests' WarpKind. a, b, c (.xyz) are the spherical triangle's
 * unit vertices, read by WARP_SPHERICAL_TRIANGLE only. */
#define WARP_HEMISPHERE_UNIFORM 0u
#define WARP_HEMISPHERE_COSINE 1u
#define WARP_SPHERICAL_TRIANGLE 2u
#define WARP_HEMISPHERE_FIBONACCI 3u /* pdf only: sampling needs (i, n), see fibonacci_* */

/* u of sample k: two hashed numbers of (k, seed). */
inline float2 test_u(uint k, uint seed) {
    uint4 h = pcg4d((uint4)(k, seed, 0x5A3Du, 0u));
    return (float2)(uint_to_unit_float(h.x), uint_to_unit_float(h.y));
}

inline float3 warp(uint kind, float4 a, float4 b, float4 c, float2 u) {
    if (kind == WARP_HEMISPHERE_UNIFORM) return sample_hemisphere_uniform(u);
    if (kind == WARP_HEMISPHERE_COSINE) return sample_hemisphere_cosine(u);
    return sample_spherical_triangle(a.xyz, b.xyz, c.xyz, u);
}

inline float warp_pdf_w(uint kind, float4 a, float4 b, float4 c, float3 w) {
    if (kind == WARP_HEMISPHERE_UNIFORM) return sample_hemisphere_uniform_pdf_w(w);
    if (kind == WARP_HEMISPHERE_COSINE) return sample_hemisphere_cosine_pdf_w(w);
    if (kind == WARP_HEMISPHERE_FIBONACCI) return sample_hemisphere_fibonacci_pdf_w(w);
    return sample_spherical_triangle_pdf_w(a.xyz, b.xyz, c.xyz, w);
}

/* Reads nothing; writes out[k] = (w, pdf_w(w)) for k < count, w sampled from test_u(k, seed). */
kernel void warp_directions(uint kind, float4 a, float4 b, float4 c, uint count, uint seed,
                            global float4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float3 w = warp(kind, a, b, c, test_u(k, seed));
    out[k] = (float4)(w, warp_pdf_w(kind, a, b, c, w));
}

/* Reads u[k]; writes out[k] = (w, pdf_w(w)) for k < count. */
kernel void warp_directions_from_u(uint kind, float4 a, float4 b, float4 c, uint count,
                                   global const float2* u, global float4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float3 w = warp(kind, a, b, c, u[k]);
    out[k] = (float4)(w, warp_pdf_w(kind, a, b, c, w));
}

/* Reads w[k].xyz; writes u[k], the inverse of the warp, for k < count. */
kernel void invert_directions(uint kind, float4 a, float4 b, float4 c, uint count,
                              global const float4* w, global float2* u) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float3 d = w[k].xyz;
    if (kind == WARP_HEMISPHERE_UNIFORM)
        u[k] = invert_hemisphere_uniform(d);
    else if (kind == WARP_HEMISPHERE_COSINE)
        u[k] = invert_hemisphere_cosine(d);
    else
        u[k] = invert_spherical_triangle(a.xyz, b.xyz, c.xyz, d);
}

/* Reads w[k].xyz; writes pdf[k] = pdf_w(w[k]) for k < count. */
kernel void pdf_directions(uint kind, float4 a, float4 b, float4 c, uint count,
                           global const float4* w, global float* pdf) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    pdf[k] = warp_pdf_w(kind, a, b, c, w[k].xyz);
}

/* Reads a, b, c (.xyz); writes out[0] = spherical_triangle_solid_angle(a, b, c). */
kernel void solid_angle(float4 a, float4 b, float4 c, global float* out) {
    if (get_global_id(0) == 0) out[0] = spherical_triangle_solid_angle(a.xyz, b.xyz, c.xyz);
}

/* Reads u[k]; writes b[k] = sample_triangle_uniform(u[k]) and back[k] =
 * invert_triangle_uniform(b[k]) for k < count; with hashed u (test_u(k, seed)) when use_hash. */
kernel void warp_triangle(uint count, uint use_hash, uint seed, global const float2* u,
                          global float2* b, global float2* back) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float2 bk = sample_triangle_uniform(use_hash ? test_u(k, seed) : u[k]);
    b[k] = bk;
    back[k] = invert_triangle_uniform(bk);
}

/* Reads nothing; writes out[s·n + i] = (point i of n, pdf_w) for sets s < sets, u shared by
 * the set: test_u(s, seed), or u_fixed when sets == 1 and use_fixed. */
kernel void fibonacci_sets(uint n, uint sets, uint seed, uint use_fixed, float2 u_fixed,
                           global float4* out) {
    uint g = (uint)get_global_id(0);
    if (g >= n * sets) return;
    uint s = g / n, i = g % n;
    float2 u = use_fixed ? u_fixed : test_u(s, seed);
    float3 w = sample_hemisphere_fibonacci(i, n, u);
    out[g] = (float4)(w, sample_hemisphere_fibonacci_pdf_w(w));
}

/* Reads nothing; writes out[k] = (w, pdf_w) for k < count: point `index` of n with u =
 * test_u(k, seed), or, when index >= n, a point whose index is drawn uniformly too. */
kernel void fibonacci_samples(uint n, uint index, uint count, uint seed, global float4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    uint i = index;
    if (i >= n) {
        float v = uint_to_unit_float(pcg4d((uint4)(k, seed, 0x5A3Du, 0u)).z);
        i = min((uint)(v * (float)n), n - 1u);
    }
    float3 w = sample_hemisphere_fibonacci(i, n, test_u(k, seed));
    out[k] = (float4)(w, sample_hemisphere_fibonacci_pdf_w(w));
}

/* Reads cdf (n + 1 entries) or the alias table (n entries) by method (0 CDF, 1 alias,
 * 2 uniform); writes out[k] = (index, pmf bits, u_remap bits, 0) for k < count, u and u_fine
 * hashed from (k, seed). */
kernel void sample_discrete(uint method, global const float* cdf, global const AliasEntry* table,
                            uint n, uint count, uint seed, global uint4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    uint4 h = pcg4d((uint4)(k, seed, 0xD15Cu, 0u));
    float u = uint_to_unit_float(h.x), u_fine = uint_to_unit_float(h.y);
    DiscreteSample s = method == 0u   ? sample_discrete_cdf(cdf, n, u, u_fine)
                       : method == 1u ? sample_discrete_alias(table, n, u, u_fine)
                                      : sample_discrete_uniform(n, u, u_fine);
    out[k] = (uint4)(s.index, as_uint(s.pmf), as_uint(s.u_remap), 0u);
}

/* Reads cdf or table as sample_discrete; writes pmf[i] = the distribution's pmf of i < n. */
kernel void discrete_pmfs(uint method, global const float* cdf, global const AliasEntry* table,
                          uint n, global float* pmf) {
    uint i = (uint)get_global_id(0);
    if (i >= n) return;
    pmf[i] = method == 0u ? discrete_cdf_pmf(cdf, i) : discrete_alias_pmf(table, i);
}

/* Reads the light tree and the lights' paths (LightTreePath); writes pmf[k · n + i] =
 * light_tree_pmf of light i < n at shading point k < count (p[k].xyz, normal[k].xyz). */
kernel void light_tree_pmfs(global const LightTreeNode* nodes, global const LightTreePath* paths, uint n,
                            uint count, global const float4* p, global const float4* normal,
                            global float* pmf) {
    uint g = (uint)get_global_id(0);
    if (g >= n * count) return;
    uint k = g / n, i = g % n;
    pmf[g] = light_tree_pmf(nodes, paths[i].bits, paths[i].length, p[k].xyz, normal[k].xyz);
}

/* Reads the tree and the paths as light_tree_pmfs; writes out[j] = (index, pmf bits, u_remap
 * bits, bits of the pmf twin light_tree_pmf of that index) for sample j < count · per_point at
 * shading point j / per_point. u: stratified, (j % per_point + 0.5) / per_point, when
 * stratified != 0, else hashed from (j, seed); u_fine hashed. */
kernel void sample_light_tree_at(global const LightTreeNode* nodes, global const LightTreePath* paths,
                                 uint count, uint per_point, uint stratified, uint seed,
                                 global const float4* p, global const float4* normal,
                                 global uint4* out) {
    uint j = (uint)get_global_id(0);
    if (j >= count * per_point) return;
    uint k = j / per_point;
    uint4 h = pcg4d((uint4)(j, seed, 0x7EE5u, 0u));
    float u = stratified != 0u ? ((float)(j % per_point) + 0.5f) / (float)per_point
                               : uint_to_unit_float(h.x);
    float u_fine = uint_to_unit_float(h.y);
    DiscreteSample s = sample_light_tree(nodes, 0, 0u, p[k].xyz, normal[k].xyz, u, u_fine);
    float twin = s.pmf > 0.0f ? light_tree_pmf(nodes, paths[s.index].bits, paths[s.index].length,
                                               p[k].xyz, normal[k].xyz)
                              : 0.0f;
    out[j] = (uint4)(s.index, as_uint(s.pmf), as_uint(s.u_remap), as_uint(twin));
}

/* Reads normal[k].xyz and v[k].xyz; writes out[4k .. 4k+3] = t, b, n of frame_from_normal and
 * (frame_to_local(frame_to_world(v))) for k < count. */
kernel void frames(uint count, global const float4* normal, global const float4* v,
                   global float4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    Frame f = frame_from_normal(normal[k].xyz);
    float3 back = frame_to_local(&f, frame_to_world(&f, v[k].xyz));
    out[4 * k + 0] = (float4)(f.t, 0.0f);
    out[4 * k + 1] = (float4)(f.b, 0.0f);
    out[4 * k + 2] = (float4)(f.n, 0.0f);
    out[4 * k + 3] = (float4)(back, 0.0f);
}
