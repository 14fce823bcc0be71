/* The GGX (Trowbridge–Reitz) microfacet model of glTF 2.0's Appendix B, in a local frame whose
 * z is the normal: distribution D, height-correlated Smith visibility V = G2/(4|n·l||n·v|),
 * Schlick Fresnel, and sampling of the visible normals (Heitz 2018, JCGT 7(4)) by the
 * spherical-cap construction of Dupuy & Benyoub 2023 ("Sampling Visible GGX Normals with
 * Spherical Caps", HPG). Compiled only for scenes with glossy materials (-D MCRT_MATERIALS_GLTF,
 * chosen by the host from the scene: DESIGN.md "Radiometric contract"). */
#ifndef MCRT_MICROFACET_CL
#define MCRT_MICROFACET_CL

#include "shared_types.h"

/* D(m) = α² / (π ((n·m)²(α² − 1) + 1)²) for n·m > 0 (Walter et al. 2007 eq. 33), written as
 * 1 / (π α² t²) with t = (m_x² + m_y²)/α² + m_z², which does not cancel near the peak when α is
 * small (α is at least MCRT_ALPHA_MIN). */
inline float ggx_d(float3 m, float alpha) {
    if (m.z <= 0.0f) return 0.0f;
    float a2 = alpha * alpha;
    float t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    return 1.0f / (M_PI_F * a2 * t * t);
}

/* √(α² + (1 − α²) cos²θ): Smith's Λ(ω) = (√(1 + α² tan²θ) − 1)/2 is (this/cosθ − 1)/2. */
inline float ggx_smith_root(float cos_theta, float alpha) {
    float a2 = alpha * alpha;
    return sqrt(fma(1.0f - a2, cos_theta * cos_theta, a2));
}

/* Masking of the direction of cosθ = c > 0: G1 = 1/(1 + Λ) = 2c / (c + √(α² + (1 − α²)c²)). */
inline float ggx_g1(float c, float alpha) { return 2.0f * c / (c + ggx_smith_root(c, alpha)); }

/* glTF Appendix B's V = G2 / (4 |n·l| |n·v|) with the height-correlated G2 = 1/(1 + Λ(l) + Λ(v))
 * (Heitz 2014, eq. 99): 0.5 / (n·l √(α² + (1 − α²)(n·v)²) + n·v √(α² + (1 − α²)(n·l)²)). */
inline float ggx_visibility(float cos_o, float cos_i, float alpha) {
    return 0.5f / (cos_i * ggx_smith_root(cos_o, alpha) + cos_o * ggx_smith_root(cos_i, alpha));
}

/* A normal m of the visible-normal density D_wo(m) = G1(wo) max(0, wo·m) D(m) / cosθ_o, for wo
 * above the surface (local, unit): Dupuy & Benyoub 2023, listing 3 — the view direction is
 * stretched to the α = 1 configuration, where the visible normals are the sum of wo and a
 * point uniform on the spherical cap z ≥ −wo_z of the unit sphere, then unstretched. */
inline float3 ggx_sample_visible_normal(float3 wo, float alpha, float2 u) {
    float3 w = normalize((float3)(wo.x * alpha, wo.y * alpha, wo.z));
    float turns = 2.0f * u.x; /* φ = π · turns */
    float z = fma(1.0f - u.y, 1.0f + w.z, -w.z);
    float sin_theta = sqrt(clamp(1.0f - z * z, 0.0f, 1.0f));
    float3 h = (float3)(sin_theta * cospi(turns), sin_theta * sinpi(turns), z) + w;
    float3 m = (float3)(h.x * alpha, h.y * alpha, h.z);
    float len2 = dot(m, m);
    return len2 > 0.0f ? m * (1.0f / sqrt(len2)) : (float3)(0.0f, 0.0f, 1.0f);
}

/* Density with respect to solid angle of wi = reflect(−wo, m) for m ~ D_wo: D_wo(m)/(4 wo·m) =
 * G1(wo) D(m) / (4 cosθ_o) with m = (wo + wi)/|wo + wi| (Heitz 2018 eq. 17; the reflection's
 * Jacobian 1/(4 wo·m), Walter et al. 2007 eq. 14). Directions below the surface are never
 * returned (the sampler rejects them), but their density is that of the construction. */
inline float ggx_reflection_pdf_w(float3 wo, float3 wi, float alpha) {
    float3 h = wo + wi;
    float len2 = dot(h, h);
    if (!(wo.z > 0.0f) || !(len2 > 0.0f)) return 0.0f;
    float3 m = h * (1.0f / sqrt(len2));
    return ggx_g1(wo.z, alpha) * ggx_d(m, alpha) / (4.0f * wo.z);
}

/* Schlick's Fresnel: F0 + (F90 − F0)(1 − cosθ)^5 (Schlick 1994; glTF Appendix B). */
inline float3 fresnel_schlick(float3 f0, float3 f90, float cos_theta) {
    float c = clamp(1.0f - cos_theta, 0.0f, 1.0f);
    float c2 = c * c;
    return fma(f90 - f0, (float3)(c2 * c2 * c), f0);
}

#endif
