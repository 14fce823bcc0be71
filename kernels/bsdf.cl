/* The surface's BSDF, reached only through eval / sample / pdf, so that an estimator written
 * against them keeps working whatever the material (docs/ESTIMATORS.md). Directions are unit and
 * in world space; wo (sp->wo) points toward the viewer, and sp->n is on its side.
 *
 * Two builds, chosen by the host from the scene (DESIGN.md "Radiometric contract": model no
 * more than a scene needs):
 *  - default: every surface is the course's Lambertian reflector, f_r = albedo/π, sampled by
 *    cosine (GI Compendium eq. 35; PBRT 3rd ed. 13.6.3);
 *  - -D MCRT_MATERIALS_GLTF: glTF 2.0's metallic-roughness BRDF (specification, Appendix B;
 *    KHR_materials_specular), f = (1 − metallic)·dielectric + metallic·metal, sampled by a lobe
 *    chosen by its estimated weight: the diffuse lobe by cosine, the specular lobe by GGX's
 *    visible normals (microfacet.cl). */
#ifndef MCRT_BSDF_CL
#define MCRT_BSDF_CL

#include "frame.cl"
#if defined(MCRT_MATERIALS_GLTF)
#include "microfacet.cl"
#endif
#include "sampling.cl"
#include "scene.cl"

typedef struct {
    float3 wi;       /* sampled direction, unit, world */
    float3 f;        /* f_r(wo, wi) */
    float pdf_w;     /* density of wi with respect to solid angle */
    float cos_theta; /* cosθ of wi about the normal, as the sampler computed it */
} BsdfSample;

/* True where wi leaves on the viewer's side of the geometric surface. Only a bent shading normal
 * (textured builds) can put a direction above the shading normal and below the surface: such a
 * direction carries no light (it would come through the surface), and a sample there is none. */
inline bool above_surface(const SurfacePoint* sp, float3 wi) {
#if defined(MCRT_TEXTURES)
    return dot(sp->ng, wi) > 0.0f;
#else
    return true;
#endif
}

inline BsdfSample below_surface_checked(const SurfacePoint* sp, BsdfSample s) {
    if (!above_surface(sp, s.wi)) {
        s.f = (float3)(0.0f);
        s.pdf_w = 0.0f;
    }
    return s;
}

#if defined(MCRT_MATERIALS_GLTF)

/* The material's parameters, unpacked (shared_types.h, Material). */
typedef struct {
    float3 base;      /* baseColor */
    float metallic;
    float alpha;      /* GGX α */
    float3 f0;        /* the dielectric's F0 (0.04 specularColor, × specularFactor) */
    float f90;        /* the dielectric's F90 (specularFactor) */
} GltfMaterial;

inline GltfMaterial gltf_material(const SurfacePoint* sp) {
    GltfMaterial m;
    m.base = sp->material.base_color.xyz;
    m.metallic = sp->material.metallic;
    m.alpha = sp->material.alpha;
    m.f0 = sp->material.specular.xyz;
    m.f90 = sp->material.specular.w;
    return m;
}

/* f_r(wo, wi) for wo, wi local and above the surface, h their half vector (glTF Appendix B):
 *   metal      = F_schlick(F0 = baseColor, F90 = 1; v·h) · D · V
 *   dielectric = (1 − F_d)·baseColor/π + F_d · D · V,  F_d = F_schlick(F0, F90; v·h)
 *   f          = mix(dielectric, metal, metallic). */
inline float3 gltf_brdf(const GltfMaterial* m, float3 wo, float3 wi) {
    float3 h = normalize(wo + wi);
    float voh = max(dot(wo, h), 0.0f);
    float specular = ggx_d(h, m->alpha) * ggx_visibility(wo.z, wi.z, m->alpha);
    float3 f_metal = fresnel_schlick(m->base, (float3)(1.0f), voh) * specular;
    float3 F = fresnel_schlick(m->f0, (float3)(m->f90), voh);
    float3 f_dielectric = (1.0f - F) * m->base * MCRT_INV_PI + F * specular;
    return mix(f_dielectric, f_metal, m->metallic);
}

/* Probability of choosing the specular lobe at cosθ_o = c: the lobes' reflectances estimated
 * with n·v in place of v·h (the Fresnel weights at the view), by luminance; 0 for a Lambertian
 * material, 1 for a black metal. */
inline float gltf_specular_probability(const GltfMaterial* m, float c) {
    const float3 Y = (float3)(0.2126f, 0.7152f, 0.0722f);
    float F_metal = dot(fresnel_schlick(m->base, (float3)(1.0f), c), Y);
    float F_dielectric = dot(fresnel_schlick(m->f0, (float3)(m->f90), c), Y);
    float specular = mix(F_dielectric, F_metal, m->metallic);
    float diffuse = (1.0f - m->metallic) * (1.0f - F_dielectric) * dot(m->base, Y);
    float total = specular + diffuse;
    return total > 0.0f ? specular / total : 0.5f;
}

/* The mixture density of the two lobes, the specular one chosen with probability p; local
 * directions, wi above the surface. */
inline float gltf_mixture_pdf_w(const GltfMaterial* m, float p, float3 wo, float3 wi) {
    return p * ggx_reflection_pdf_w(wo, wi, m->alpha) + (1.0f - p) * wi.z * MCRT_INV_PI;
}

inline float gltf_pdf_w(const GltfMaterial* m, float3 wo, float3 wi) {
    if (!(wi.z > 0.0f) || !(wo.z > 0.0f)) return 0.0f;
    return gltf_mixture_pdf_w(m, gltf_specular_probability(m, wo.z), wo, wi);
}

/* f_r(wo, wi) at sp: 0 unless both directions are on the side of the normal. */
inline float3 bsdf_eval(const SurfacePoint* sp, float3 wi) {
    Frame frame = frame_from_normal(sp->n);
    float3 wo_l = frame_to_local(&frame, sp->wo), wi_l = frame_to_local(&frame, wi);
    if (!(wo_l.z > 0.0f) || !(wi_l.z > 0.0f) || !above_surface(sp, wi)) return (float3)(0.0f);
    GltfMaterial m = gltf_material(sp);
    return gltf_brdf(&m, wo_l, wi_l);
}

/* A direction by the BSDF's density: u.x first chooses the lobe and is rescaled linearly to
 * [0, 1) within the choice (one number for the choice and the direction), then (u.x, u.y)
 * samples that lobe.
 * f and pdf_w are those of the whole BSDF (both lobes); a specular sample reflected below the
 * surface is returned with pdf_w = 0 (no direction: the estimators skip it). */
inline BsdfSample bsdf_sample(const SurfacePoint* sp, float2 u) {
    Frame frame = frame_from_normal(sp->n);
    float3 wo = frame_to_local(&frame, sp->wo);
    GltfMaterial m = gltf_material(sp);
    BsdfSample s;
    s.f = (float3)(0.0f);
    s.pdf_w = 0.0f;
    s.cos_theta = 0.0f;
    s.wi = sp->n;
    if (!(wo.z > 0.0f)) return s;
    float p = gltf_specular_probability(&m, wo.z);
    float3 wi;
    if (u.x < p) {
        u.x = min(u.x / p, 0x1.fffffep-1f);
        float3 h = ggx_sample_visible_normal(wo, m.alpha, u);
        wi = 2.0f * dot(wo, h) * h - wo;
    } else {
        u.x = min((u.x - p) / (1.0f - p), 0x1.fffffep-1f);
        wi = sample_hemisphere_cosine(u);
    }
    if (!(wi.z > 0.0f)) return s;
    wi = normalize(wi);
    s.wi = frame_to_world(&frame, wi);
    s.f = gltf_brdf(&m, wo, wi);
    s.pdf_w = gltf_mixture_pdf_w(&m, p, wo, wi);
    s.cos_theta = wi.z;
    return below_surface_checked(sp, s);
}

/* Density with respect to solid angle of bsdf_sample returning wi (the twin MIS needs). */
inline float bsdf_pdf_w(const SurfacePoint* sp, float3 wi) {
    Frame frame = frame_from_normal(sp->n);
    GltfMaterial m = gltf_material(sp);
    return gltf_pdf_w(&m, frame_to_local(&frame, sp->wo), frame_to_local(&frame, wi));
}

#else /* Lambertian */

/* f_r(wo, wi) at sp: albedo/π for directions on the side of the normal, else 0. */
inline float3 bsdf_eval(const SurfacePoint* sp, float3 wi) {
    return dot(sp->n, wi) > 0.0f && above_surface(sp, wi) ? sp->material.base_color.xyz * MCRT_INV_PI
                                                           : (float3)(0.0f);
}

/* A direction by the BSDF's own density (cosine-weighted for the Lambertian lobe), from u. */
inline BsdfSample bsdf_sample(const SurfacePoint* sp, float2 u) {
    Frame frame = frame_from_normal(sp->n);
    float3 w = sample_hemisphere_cosine(u);
    BsdfSample s;
    s.wi = frame_to_world(&frame, w);
    s.f = sp->material.base_color.xyz * MCRT_INV_PI;
    s.pdf_w = sample_hemisphere_cosine_pdf_w(w);
    s.cos_theta = w.z;
    return below_surface_checked(sp, s);
}

/* Density with respect to solid angle of bsdf_sample returning wi (the twin MIS needs). */
inline float bsdf_pdf_w(const SurfacePoint* sp, float3 wi) {
    Frame frame = frame_from_normal(sp->n);
    return sample_hemisphere_cosine_pdf_w(frame_to_local(&frame, wi));
}

#endif

/* The reflectance the ambient estimators use: the course keeps them Lambertian. */
inline float3 surface_albedo(const SurfacePoint* sp) { return sp->material.base_color.xyz; }

#endif
