/* The surface's BSDF, reached only through eval / sample / pdf, so that an estimator written
 * against them keeps working when the materials grow (docs/ESTIMATORS.md). Today every surface
 * is the course's Lambertian reflector, f_r = albedo/π, sampled by cosine (GI Compendium eq. 35;
 * PBRT 3rd ed. 13.6.3). Directions are unit and in world space; wo points toward the viewer. */
#ifndef MCRT_BSDF_CL
#define MCRT_BSDF_CL

#include "frame.cl"
#include "sampling.cl"
#include "scene.cl"

typedef struct {
    float3 wi;       /* sampled direction, unit, world */
    float3 f;        /* f_r(wo, wi) */
    float pdf_w;     /* density of wi with respect to solid angle */
    float cos_theta; /* cosθ of wi about the normal, as the sampler computed it */
} BsdfSample;

/* f_r(wo, wi) at sp: albedo/π for directions on the side of the normal, else 0. */
inline float3 bsdf_eval(const SurfacePoint* sp, float3 wi) {
    return dot(sp->n, wi) > 0.0f ? sp->material.albedo.xyz * MCRT_INV_PI : (float3)(0.0f);
}

/* A direction by the BSDF's own density (cosine-weighted for the Lambertian lobe), from u. */
inline BsdfSample bsdf_sample(const SurfacePoint* sp, float2 u) {
    Frame frame = frame_from_normal(sp->n);
    float3 w = sample_hemisphere_cosine(u);
    BsdfSample s;
    s.wi = frame_to_world(&frame, w);
    s.f = sp->material.albedo.xyz * MCRT_INV_PI;
    s.pdf_w = sample_hemisphere_cosine_pdf_w(w);
    s.cos_theta = w.z;
    return s;
}

/* Density with respect to solid angle of bsdf_sample returning wi (the twin MIS needs). */
inline float bsdf_pdf_w(const SurfacePoint* sp, float3 wi) {
    Frame frame = frame_from_normal(sp->n);
    return sample_hemisphere_cosine_pdf_w(frame_to_local(&frame, wi));
}

/* The reflectance the ambient estimators use: the course keeps them Lambertian. */
inline float3 surface_albedo(const SurfacePoint* sp) { return sp->material.albedo.xyz; }

#endif
