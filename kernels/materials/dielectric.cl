/* The dielectric interface of transmissive materials (KHR_materials_transmission, _ior,
 * _volume), in the local frame of bsdf.cl (z the normal on the viewer's side, wo.z > 0): the
 * exact unpolarised Fresnel term, refraction, the rough dielectric BTDF of Walter et al. 2007
 * with GGX visible normals, and Beer–Lambert attenuation inside a volume. eta is the relative
 * index η_t/η_i across the interface seen from wo's side; 0 stands for KHR_materials_ior's ior 0,
 * whose Fresnel term is 1 everywhere. Compiled only for scenes with a transmissive material
 * (-D MCRT_TRANSMISSION). */
#ifndef MCRT_DIELECTRIC_CL
#define MCRT_DIELECTRIC_CL

#include "microfacet.cl"

/* Fresnel reflectance of unpolarised light arriving at cosθ_i = c (≥ 0) from the side of index
 * η_i (PBRT 4th ed. §9.3.6, eqs. 9.5–9.6; r∥ and r⊥ from Snell's law); 1 under total internal
 * reflection and for eta 0. */
inline float fresnel_dielectric(float c, float eta) {
    if (!(eta > 0.0f)) return 1.0f;
    c = clamp(c, 0.0f, 1.0f);
    float sin2_t = (1.0f - c * c) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    float c_t = sqrt(1.0f - sin2_t);
    float r_parallel = (eta * c - c_t) / (eta * c + c_t);
    float r_perpendicular = (c - eta * c_t) / (c + eta * c_t);
    return 0.5f * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

/* The direction refracted from wo (unit, wo·m > 0) through the interface of normal m, in *wt;
 * false under total internal reflection (PBRT 4th ed. §9.3.2, eq. 9.4). */
inline bool refract_direction(float3 wo, float3 m, float eta, float3* wt) {
    float c = dot(wo, m);
    float sin2_t = (1.0f - c * c) / (eta * eta);
    if (!(eta > 0.0f) || sin2_t >= 1.0f) return false;
    float c_t = sqrt(1.0f - sin2_t);
    *wt = normalize(-wo / eta + (c / eta - c_t) * m);
    return true;
}

/* Walter et al. 2007's generalised half vector of a refraction from wo to wi (eq. 16):
 * m ∝ −(η_i wo + η_t wi), turned to z > 0; false where wi is no refraction of wo through any
 * microfacet (both on one side of m) or m is degenerate. */
inline bool refraction_half_vector(float3 wo, float3 wi, float eta, float3* m) {
    float3 h = wo + eta * wi;
    float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return false;
    h = h * (1.0f / sqrt(len2));
    if (h.z < 0.0f) h = -h;
    *m = h;
    return dot(wo, h) > 0.0f && dot(wi, h) < 0.0f;
}

/* |∂ω_m/∂ω_i| of a refraction, |wi·m| / (wi·m + wo·m/η)² (Walter et al. 2007, eq. 17, with η_o
 * and η_i written as the ratio eta = η_t/η_i). */
inline float refraction_jacobian(float3 wo, float3 wi, float3 m, float eta) {
    float d = dot(wi, m) + dot(wo, m) / eta;
    return fabs(dot(wi, m)) / (d * d);
}

/* The rough dielectric BTDF for wi below (wi.z < 0), without the Fresnel factor (1 − F) and the
 * tint: D(m) G2 |wi·m| |wo·m| / (|wi.z| wo.z (wi·m + wo·m/η)²) / η² (Walter et al. 2007 eq. 21;
 * the 1/η² of radiance crossing into a denser medium, PBRT 4th ed. §9.5.2), with the
 * height-correlated G2 = 4 |wi.z| wo.z V of microfacet.cl. */
inline float ggx_refraction_f(float3 wo, float3 wi, float3 m, float eta, float alpha) {
    float V = ggx_visibility(wo.z, -wi.z, alpha);
    float d = dot(wi, m) + dot(wo, m) / eta;
    return 4.0f * ggx_d(m, alpha) * V * fabs(dot(wi, m)) * dot(wo, m) / (d * d) / (eta * eta);
}

/* Density with respect to solid angle of wi refracted through m ~ D_wo (Heitz 2018 eq. 17 with
 * Walter's Jacobian): G1(wo) max(0, wo·m) D(m) / wo.z · |∂ω_m/∂ω_i|. */
inline float ggx_refraction_pdf_w(float3 wo, float3 wi, float3 m, float eta, float alpha) {
    float visible = ggx_g1(wo.z, alpha) * dot(wo, m) * ggx_d(m, alpha) / wo.z;
    return visible * refraction_jacobian(wo, wi, m, eta);
}

/* Transmittance 2^(−a·t) per channel over a distance t inside a volume whose attenuation per
 * unit length, in bits, is a = −log2(attenuationColor)/attenuationDistance (KHR_materials_volume:
 * Beer–Lambert; host/render/gpu_scene.cpp). 0·t = 0 even for t = MAXFLOAT, and a·t overflowing
 * to ∞ gives 0: no NaN. */
inline float3 beer_lambert(float3 a, float t) {
    return (float3)(exact_exp2(-(a.x * t)), exact_exp2(-(a.y * t)), exact_exp2(-(a.z * t)));
}

#endif
