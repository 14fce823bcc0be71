/* The surface's BSDF, reached only through eval / sample / pdf, so that an estimator written
 * against them keeps working whatever the material (docs/ESTIMATORS.md). Directions are unit and
 * in world space; wo (sp->wo) points toward the viewer, and sp->n is on its side.
 *
 * Three builds, chosen by the host from the scene (DESIGN.md "Radiometric contract": model no
 * more than a scene needs):
 *  - default: every surface is the course's Lambertian reflector, f_r = albedo/π, sampled by
 *    cosine (GI Compendium eq. 35; PBRT 3rd ed. 13.6.3);
 *  - -D MCRT_MATERIALS_GLTF: glTF 2.0's metallic-roughness BRDF (specification, Appendix B;
 *    KHR_materials_specular), f = (1 − metallic)·dielectric + metallic·metal, sampled by a lobe
 *    chosen by its estimated weight: the diffuse lobe by cosine, the specular lobe by GGX's
 *    visible normals (microfacet.cl);
 *  - -D MCRT_TRANSMISSION as well (a scene with KHR_materials_transmission): a third lobe of
 *    glass, reflecting and transmitting through a dielectric interface (dielectric.cl), thin-walled
 *    or bounding a volume, a pair of deltas when smooth. */
#ifndef MCRT_BSDF_CL
#define MCRT_BSDF_CL

#include "frame.cl"
#if defined(MCRT_MATERIALS_GLTF)
#include "microfacet.cl"
#endif
#if defined(MCRT_TRANSMISSION)
#if !defined(MCRT_MATERIALS_GLTF)
#error "MCRT_TRANSMISSION needs MCRT_MATERIALS_GLTF (host/render/variants.cpp)"
#endif
#include "dielectric.cl"
#endif
#include "sampling.cl"
#include "scene.cl"

/* BsdfSample.lobe (transmissive builds): what kind of direction a sample is. A delta sample's f
 * and pdf_w are a point mass's (pdf_w its probability, f such that f·cos_theta/pdf_w is its
 * weight), which bsdf_eval and bsdf_pdf_w never return; a transmitted one leaves through the
 * surface, where no light strategy looks. */
#define BSDF_LOBE_DELTA 1u
#define BSDF_LOBE_TRANSMITTED 2u

typedef struct {
    float3 wi;       /* sampled direction, unit, world */
    float3 f;        /* f(wo, wi) */
    float pdf_w;     /* density of wi with respect to solid angle */
    float cos_theta; /* |cosθ| of wi about the normal, as the sampler computed it */
#if defined(MCRT_TRANSMISSION)
    uint lobe; /* BSDF_LOBE_* bits; 0: a continuous reflection */
#endif
} BsdfSample;

/* True where the light strategies could have produced the sample's direction: a continuous
 * density on the viewer's side. The direct-light estimators count only these; the path counts
 * what the others find (path.cl), so that no light is counted twice or missed (DESIGN.md:
 * shadow rays do not pass transmissive surfaces). Always true without transmission. */
inline bool bsdf_sample_is_direct(const BsdfSample* s) {
#if defined(MCRT_TRANSMISSION)
    return s->lobe == 0u;
#else
    return true;
#endif
}

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
#if defined(MCRT_TRANSMISSION) && defined(MCRT_TEXTURES)
    /* A transmitted direction must leave through the geometric surface, a reflected one not. */
    bool through = (s.lobe & BSDF_LOBE_TRANSMITTED) != 0u;
    if (through ? !(dot(sp->ng, s.wi) < 0.0f) : !above_surface(sp, s.wi)) {
#else
    if (!above_surface(sp, s.wi)) {
#endif
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
    float3 f0;        /* the dielectric's F0 (f0(ior) specularColor, × specularFactor) */
    float f90;        /* the dielectric's F90 (specularFactor) */
#if defined(MCRT_TRANSMISSION)
    float transmission; /* transmissionFactor: the share of the dielectric that is glass */
    float eta;          /* η_t/η_i seen from wo's side: ior, or 1/ior leaving a volume; 0: F = 1 */
    bool thin;          /* no volume: light passes straight through (thin-walled) */
    bool smooth;        /* the glass lobe is a pair of deltas (α at its floor, or no refraction) */
#endif
} GltfMaterial;

inline GltfMaterial gltf_material(const SurfacePoint* sp) {
    GltfMaterial m;
    m.base = sp->material.base_color.xyz;
    m.metallic = sp->material.metallic;
    m.alpha = sp->material.alpha;
    m.f0 = sp->material.specular.xyz;
    m.f90 = sp->material.specular.w;
#if defined(MCRT_TRANSMISSION)
    /* A volume's outside is its front (counter-clockwise) side, as glTF's outward normals. */
    float ior = sp->material.ior;
    m.transmission = sp->material.transmission;
    m.thin = (sp->material.flags & MATERIAL_VOLUME) == 0u;
    m.eta = m.thin || sp->front ? ior : (ior > 0.0f ? 1.0f / ior : 0.0f);
    m.smooth = m.alpha <= MCRT_ALPHA_MIN || (!m.thin && m.eta == 1.0f);
#endif
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

#if defined(MCRT_TRANSMISSION)

/* ---- Transmissive materials (KHR_materials_transmission) ---------------------------------
 * f = mix((1 − T)·dielectric + T·glass, metal, metallic), T = transmissionFactor (the extension's
 * mix of the diffuse base and the specular BTDF), where the glass lobe reflects F·D·V and
 * transmits (1 − F)·baseColor × the BTDF with F the exact Fresnel term of eta (dielectric.cl).
 * Thin-walled, the transmitted lobe is the reflected one mirrored through the surface (light
 * passes straight through); bounding a volume, it is Walter et al. 2007's refraction. Smooth, the
 * glass lobe is a pair of deltas, which bsdf_eval and bsdf_pdf_w leave out. */

/* Probabilities of sampling each lobe at cosθ_o = c, by their reflectances estimated at the view
 * (luminance; Fresnel at n·v): the GGX reflection (metal and the opaque dielectric's layer), the
 * diffuse base, the glass; and the glass's exact Fresnel term at n·v, R. */
typedef struct {
    float specular, diffuse, glass;
    float reflect; /* R */
} GltfLobes;

inline GltfLobes gltf_lobes(const GltfMaterial* m, float c) {
    const float3 Y = (float3)(0.2126f, 0.7152f, 0.0722f);
    float F_metal = dot(fresnel_schlick(m->base, (float3)(1.0f), c), Y);
    float F_dielectric = dot(fresnel_schlick(m->f0, (float3)(m->f90), c), Y);
    float opaque = (1.0f - m->metallic) * (1.0f - m->transmission);
    GltfLobes l;
    l.reflect = fresnel_dielectric(c, m->eta);
    float specular = m->metallic * F_metal + opaque * F_dielectric;
    float diffuse = opaque * (1.0f - F_dielectric) * dot(m->base, Y);
    float glass = (1.0f - m->metallic) * m->transmission *
                  (l.reflect + (1.0f - l.reflect) * dot(m->base, Y));
    float total = specular + diffuse + glass;
    if (!(total > 0.0f)) {
        l.specular = l.diffuse = 0.5f;
        l.glass = 0.0f;
    } else if (glass > 0.0f) {
        l.specular = specular / total;
        l.diffuse = diffuse / total;
        l.glass = max(1.0f - l.specular - l.diffuse, 0.0f);
    } else {
        l.specular = specular / total;
        l.diffuse = 1.0f - l.specular;
        l.glass = 0.0f;
    }
    return l;
}

/* Probability that the glass lobe reflects: the Fresnel term at the view R for a smooth surface
 * (exact for both deltas); for a rough one R kept within [1/8, 7/8], since microfacets tilted
 * from the normal refract where the view itself is totally reflected (and reflect where it
 * mostly refracts), so both branches must stay possible. 1 for eta 0 (KHR_materials_ior's 0). */
inline float glass_reflect_probability(const GltfMaterial* m, const GltfLobes* l) {
    if (m->smooth || !(m->eta > 0.0f)) return l->reflect;
    return clamp(l->reflect, 0.125f, 0.875f);
}

/* The BSDF's continuous part, f(wo, wi) for local wo above the surface and any wi. */
inline float3 gltf_bsdf(const GltfMaterial* m, float3 wo, float3 wi) {
    float w_glass = (1.0f - m->metallic) * m->transmission;
    if (wi.z > 0.0f) {
        float3 h = normalize(wo + wi);
        float voh = max(dot(wo, h), 0.0f);
        float specular = ggx_d(h, m->alpha) * ggx_visibility(wo.z, wi.z, m->alpha);
        float3 f_metal = fresnel_schlick(m->base, (float3)(1.0f), voh) * specular;
        float3 F = fresnel_schlick(m->f0, (float3)(m->f90), voh);
        float3 f_dielectric =
            ((1.0f - F) * m->base * MCRT_INV_PI + F * specular) * (1.0f - m->transmission);
        float3 f = mix(f_dielectric, f_metal, m->metallic);
        if (!m->smooth && w_glass > 0.0f)
            f += (float3)(w_glass * fresnel_dielectric(voh, m->eta) * specular);
        return f;
    }
    if (m->smooth || !(w_glass > 0.0f) || !(m->eta > 0.0f) || !(wi.z < 0.0f))
        return (float3)(0.0f);
    if (m->thin) {
        float3 wr = (float3)(wi.x, wi.y, -wi.z);
        float3 h = normalize(wo + wr);
        float F = fresnel_dielectric(dot(wo, h), m->eta);
        float t = ggx_d(h, m->alpha) * ggx_visibility(wo.z, wr.z, m->alpha);
        return w_glass * (1.0f - F) * t * m->base;
    }
    float3 h;
    if (!refraction_half_vector(wo, wi, m->eta, &h)) return (float3)(0.0f);
    float F = fresnel_dielectric(dot(wo, h), m->eta);
    return w_glass * (1.0f - F) * ggx_refraction_f(wo, wi, h, m->eta, m->alpha) * m->base;
}

/* Density of bsdf_sample's continuous samples at wi (local; wo above the surface). */
inline float gltf_bsdf_pdf_w(const GltfMaterial* m, const GltfLobes* l, float3 wo, float3 wi) {
    float p_reflect = glass_reflect_probability(m, l);
    if (wi.z > 0.0f) {
        float specular = l->specular + (m->smooth ? 0.0f : l->glass * p_reflect);
        return specular * ggx_reflection_pdf_w(wo, wi, m->alpha) + l->diffuse * wi.z * MCRT_INV_PI;
    }
    if (m->smooth || !(l->glass > 0.0f) || !(m->eta > 0.0f) || !(wi.z < 0.0f)) return 0.0f;
    float p = l->glass * (1.0f - p_reflect);
    if (m->thin) return p * ggx_reflection_pdf_w(wo, (float3)(wi.x, wi.y, -wi.z), m->alpha);
    float3 h;
    if (!refraction_half_vector(wo, wi, m->eta, &h)) return 0.0f;
    return p * ggx_refraction_pdf_w(wo, wi, h, m->eta, m->alpha);
}

/* True where wi (world) is on the side of the geometric surface that its local z says: a bent
 * normal (textured builds) can put a direction above the shading normal and below the surface,
 * or the other way round; such a direction carries no light. */
inline bool on_its_side(const SurfacePoint* sp, float3 wi, float z) {
#if defined(MCRT_TEXTURES)
    return z > 0.0f ? dot(sp->ng, wi) > 0.0f : dot(sp->ng, wi) < 0.0f;
#else
    return true;
#endif
}

/* f(wo, wi) at sp, its continuous part: reflection above the surface, rough transmission below. */
inline float3 bsdf_eval(const SurfacePoint* sp, float3 wi) {
    Frame frame = frame_from_normal(sp->n);
    float3 wo_l = frame_to_local(&frame, sp->wo), wi_l = frame_to_local(&frame, wi);
    if (!(wo_l.z > 0.0f) || wi_l.z == 0.0f || !on_its_side(sp, wi, wi_l.z)) return (float3)(0.0f);
    GltfMaterial m = gltf_material(sp);
    return gltf_bsdf(&m, wo_l, wi_l);
}

/* The glass lobe's delta sample when it is smooth: the mirror direction with probability R (the
 * Fresnel term at the view), else straight through (thin-walled) or refracted (a volume), tinted
 * by the base colour and, entering or leaving a volume, scaled by 1/η² (PBRT 4th ed. §9.5.2). */
inline BsdfSample gltf_glass_delta(const GltfMaterial* m, const GltfLobes* l, float3 wo,
                                   bool reflect, BsdfSample s) {
    float w_glass = (1.0f - m->metallic) * m->transmission;
    float3 wi;
    float3 weight;
    if (reflect) {
        wi = (float3)(-wo.x, -wo.y, wo.z);
        weight = (float3)(w_glass * l->reflect);
        s.pdf_w = l->glass * l->reflect;
        s.lobe = BSDF_LOBE_DELTA;
    } else {
        if (m->thin) {
            wi = -wo;
        } else if (!refract_direction(wo, (float3)(0.0f, 0.0f, 1.0f), m->eta, &wi)) {
            return s;
        }
        float scale = m->thin ? 1.0f : 1.0f / (m->eta * m->eta);
        weight = w_glass * (1.0f - l->reflect) * scale * m->base;
        s.pdf_w = l->glass * (1.0f - l->reflect);
        s.lobe = BSDF_LOBE_DELTA | BSDF_LOBE_TRANSMITTED;
    }
    s.cos_theta = fabs(wi.z);
    if (!(s.cos_theta > 0.0f) || !(s.pdf_w > 0.0f)) {
        s.pdf_w = 0.0f;
        return s;
    }
    s.wi = wi;
    s.f = weight / s.cos_theta;
    return s;
}

/* A direction by the BSDF's density: u.x first chooses the lobe (GGX reflection, diffuse, glass)
 * and is rescaled linearly to [0, 1) within the choice, then, for the glass, chooses reflection
 * (probability R at the view) or transmission and is rescaled again; (u.x, u.y) then samples the
 * lobe: cosine for the diffuse one, GGX's visible normals for the others, reflected, mirrored
 * through the surface (thin-walled) or refracted (a volume). A continuous sample's f and pdf_w are
 * those of the whole continuous BSDF; a delta sample's those of its point mass (lobe says which).
 * A direction that ends on the wrong side of the surface is no sample (pdf_w = 0). */
inline BsdfSample bsdf_sample(const SurfacePoint* sp, float2 u) {
    Frame frame = frame_from_normal(sp->n);
    float3 wo = frame_to_local(&frame, sp->wo);
    GltfMaterial m = gltf_material(sp);
    BsdfSample s;
    s.f = (float3)(0.0f);
    s.pdf_w = 0.0f;
    s.cos_theta = 0.0f;
    s.wi = sp->n;
    s.lobe = 0u;
    if (!(wo.z > 0.0f)) return s;
    GltfLobes l = gltf_lobes(&m, wo.z);
    float3 wi;
    if (u.x < l.specular) {
        u.x = min(u.x / l.specular, 0x1.fffffep-1f);
        float3 h = ggx_sample_visible_normal(wo, m.alpha, u);
        wi = 2.0f * dot(wo, h) * h - wo;
    } else if (u.x < l.specular + l.diffuse || !(l.glass > 0.0f)) {
        u.x = min((u.x - l.specular) / l.diffuse, 0x1.fffffep-1f);
        wi = sample_hemisphere_cosine(u);
    } else {
        u.x = clamp((u.x - l.specular - l.diffuse) / l.glass, 0.0f, 0x1.fffffep-1f);
        float p_reflect = glass_reflect_probability(&m, &l);
        bool reflect = u.x < p_reflect;
        u.x = reflect ? min(u.x / p_reflect, 0x1.fffffep-1f)
                      : clamp((u.x - p_reflect) / (1.0f - p_reflect), 0.0f, 0x1.fffffep-1f);
        if (m.smooth) {
            s = gltf_glass_delta(&m, &l, wo, reflect, s);
            if (!(s.pdf_w > 0.0f)) return s;
            s.wi = frame_to_world(&frame, s.wi);
            return below_surface_checked(sp, s);
        }
        float3 h = ggx_sample_visible_normal(wo, m.alpha, u);
        wi = 2.0f * dot(wo, h) * h - wo;
        if (!reflect) {
            if (m.thin) {
                if (!(wi.z > 0.0f)) return s;
                wi.z = -wi.z;
            } else if (!refract_direction(wo, h, m.eta, &wi)) {
                return s;
            }
            if (!(wi.z < 0.0f)) return s;
            wi = normalize(wi);
            s.wi = frame_to_world(&frame, wi);
            s.f = gltf_bsdf(&m, wo, wi);
            s.pdf_w = gltf_bsdf_pdf_w(&m, &l, wo, wi);
            s.cos_theta = -wi.z;
            s.lobe = BSDF_LOBE_TRANSMITTED;
            return below_surface_checked(sp, s);
        }
    }
    if (!(wi.z > 0.0f)) return s;
    wi = normalize(wi);
    s.wi = frame_to_world(&frame, wi);
    s.f = gltf_bsdf(&m, wo, wi);
    s.pdf_w = gltf_bsdf_pdf_w(&m, &l, wo, wi);
    s.cos_theta = wi.z;
    return below_surface_checked(sp, s);
}

/* Density with respect to solid angle of bsdf_sample returning wi as a continuous sample (the
 * twin MIS needs; delta samples have none). */
inline float bsdf_pdf_w(const SurfacePoint* sp, float3 wi) {
    Frame frame = frame_from_normal(sp->n);
    GltfMaterial m = gltf_material(sp);
    float3 wo = frame_to_local(&frame, sp->wo);
    if (!(wo.z > 0.0f)) return 0.0f;
    GltfLobes l = gltf_lobes(&m, wo.z);
    return gltf_bsdf_pdf_w(&m, &l, wo, frame_to_local(&frame, wi));
}

#else /* glTF metallic-roughness, opaque */

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

#endif /* MCRT_TRANSMISSION */

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
