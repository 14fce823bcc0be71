/* Test entry points for the glTF BSDF (tests/materials/test_materials.cpp), built with
 * -D MCRT_MATERIALS_GLTF: a surface point on the plane z = 0 (normal +z) seen from direction wo,
 * with the material passed by value (shared_types.h, Material). Global sizes
 * are 1D; each entry checks its bound. */
#include "shared_types.h"
#include "bsdf.cl"
#include "rng.cl"

inline SurfacePoint test_surface(Material material, float3 wo) {
    SurfacePoint sp;
    sp.p = sp.p_error = (float3)(0.0f);
    sp.n = (float3)(0.0f, 0.0f, 1.0f);
    sp.ng = sp.n;
    sp.wo = wo;
    sp.front = true;
    sp.light = 0u;
    sp.lane = MCRT_NO_HIT;
    sp.material = material;
    return sp;
}

/* Writes out[k] = (wi, pdf_w) and f[k] = (f, cos_theta) of bsdf_sample with u hashed from
 * (k, seed); pdf_w = 0 for no direction. */
kernel void bsdf_samples(Material material, float4 wo, uint count,
                         uint seed, global float4* out, global float4* f) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    SurfacePoint sp = test_surface(material, wo.xyz);
    uint4 h = pcg4d((uint4)(k, seed, 0xB5DFu, 0u));
    BsdfSample s = bsdf_sample(&sp, (float2)(uint_to_unit_float(h.x), uint_to_unit_float(h.y)));
    out[k] = (float4)(s.wi, s.pdf_w);
    f[k] = (float4)(s.f, s.cos_theta);
}

/* Reads wi[k].xyz; writes pdf[k] = bsdf_pdf_w and f[k].xyz = bsdf_eval at wo. */
kernel void bsdf_evaluate(Material material, float4 wo, uint count,
                          global const float4* wi, global float* pdf, global float4* f) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    SurfacePoint sp = test_surface(material, wo.xyz);
    pdf[k] = bsdf_pdf_w(&sp, wi[k].xyz);
    f[k] = (float4)(bsdf_eval(&sp, wi[k].xyz), 0.0f);
}

/* Reads pairs[2k], pairs[2k + 1] (wo, wi); writes f[2k] = f(wo, wi), f[2k + 1] = f(wi, wo). */
kernel void bsdf_swapped(Material material, uint count,
                         global const float4* pairs, global float4* f) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float3 a = pairs[2 * k].xyz, b = pairs[2 * k + 1].xyz;
    SurfacePoint sa = test_surface(material, a);
    SurfacePoint sb = test_surface(material, b);
    f[2 * k] = (float4)(bsdf_eval(&sa, b), 0.0f);
    f[2 * k + 1] = (float4)(bsdf_eval(&sb, a), 0.0f);
}

/* Reads m[k].xyz (unit normals); writes d[k] = (D(m), D_wo(m) = G1(wo) max(0, wo·m) D(m)/wo_z,
 * 0, 0) for GGX of this alpha. */
kernel void ggx_distribution(float alpha, float4 wo, uint count, global const float4* m,
                             global float4* d) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float3 n = m[k].xyz;
    float D = ggx_d(n, alpha);
    float visible = ggx_g1(wo.z, alpha) * max(0.0f, dot(wo.xyz, n)) * D / wo.z;
    d[k] = (float4)(D, visible, 0.0f, 0.0f);
}

#if defined(MCRT_TRANSMISSION)
/* Transmissive builds (-D MCRT_TRANSMISSION, tests/materials/test_glass.cpp): as bsdf_samples and
 * bsdf_evaluate for a surface point seen from its front (front ≠ 0) or back face; out[k] = (wi,
 * pdf_w), f[k] = (f, cos_theta), lobe[k] the sample's BSDF_LOBE_* bits. */
kernel void glass_samples(Material material, float4 wo, uint front, uint count, uint seed,
                          global float4* out, global float4* f, global uint* lobe) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    SurfacePoint sp = test_surface(material, wo.xyz);
    sp.front = front != 0u;
    uint4 h = pcg4d((uint4)(k, seed, 0x6CA5u, 0u));
    BsdfSample s = bsdf_sample(&sp, (float2)(uint_to_unit_float(h.x), uint_to_unit_float(h.y)));
    out[k] = (float4)(s.wi, s.pdf_w);
    f[k] = (float4)(s.f, s.cos_theta);
    lobe[k] = s.lobe;
}

kernel void glass_evaluate(Material material, float4 wo, uint front, uint count,
                           global const float4* wi, global float* pdf, global float4* f) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    SurfacePoint sp = test_surface(material, wo.xyz);
    sp.front = front != 0u;
    pdf[k] = bsdf_pdf_w(&sp, wi[k].xyz);
    f[k] = (float4)(bsdf_eval(&sp, wi[k].xyz), 0.0f);
}

/* out[k] = (exact_exp2(x[k]), fresnel_dielectric(c[k], eta), 0, 0). */
kernel void dielectric_values(uint count, float eta, global const float2* xc, global float2* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    out[k] = (float2)(exact_exp2(xc[k].x), fresnel_dielectric(xc[k].y, eta));
}
#endif
