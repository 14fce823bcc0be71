/* The built-in estimators of the radiance reflected at a surface point toward the viewer
 * (DESIGN.md "Estimators"), each one function of the signature every estimator has:
 *
 *     float3 estimate_NAME(const SceneView* scene, const SurfacePoint* sp,
 *                          const SampleStream* stream, uint* rays)
 *
 * written only against the public API (api.cl: the sample stream, the BSDF, the light
 * strategies, visibility), as a user's --estimator-file is. The host picks one with
 * -D MCRT_ESTIMATE=estimate_NAME from its table of variants (host/render/variants.cpp). */
#ifndef MCRT_ESTIMATORS_CL
#define MCRT_ESTIMATORS_CL

#include "api.cl"

/* ---- Integrating over points on a light ------------------------------------------------- */

/* The random variable is (light, point) with density pmf(light)/area; the area measure becomes
 * solid angle through cosθ_y / d² (PBRT 3rd ed. 14.2.2; Veach 1997 eq. 8.4). */
inline float3 estimate_light_area(const SceneView* scene, const SurfacePoint* sp,
                                  const SampleStream* stream, uint* rays) {
    LightSample ls = sample_light_area(scene, sp, sample_2d(stream, DIM_LIGHT),
                                       sample_1d(stream, DIM_LIGHT_FINE));
    float cos_x = dot(sp->n, ls.wi);
    if (!ls.valid || cos_x <= 0.0f) return (float3)(0.0f); /* behind the receiver */
    *rays += 1u;
    if (!light_sample_visible(scene, sp, &ls)) return (float3)(0.0f);
    return bsdf_eval(sp, ls.wi) * ls.Le * light_sample_weight(&ls, cos_x);
}

/* ---- Integrating over the solid angle of a light ---------------------------------------- */

/* Directions uniform in the spherical triangle the chosen light subtends (Arvo 1995). */
inline float3 estimate_light_solid_angle(const SceneView* scene, const SurfacePoint* sp,
                                         const SampleStream* stream, uint* rays) {
    LightSample ls = sample_light_solid_angle(scene, sp, sample_2d(stream, DIM_LIGHT),
                                              sample_1d(stream, DIM_LIGHT_FINE));
    float cos_x = dot(sp->n, ls.wi);
    if (!ls.valid || cos_x <= 0.0f) return (float3)(0.0f);
    *rays += 1u;
    if (!light_sample_visible(scene, sp, &ls)) return (float3)(0.0f);
    return bsdf_eval(sp, ls.wi) * ls.Le * light_sample_weight(&ls, cos_x);
}

/* ---- Integrating over directions --------------------------------------------------------- */

/* f·Le·cosθ / pdf(ω) for a direction w (local frame, z up) of density pdf_w drawn from the
 * numbers u, that finds an emitter or leaves the scene toward the sky light (GI Compendium
 * eqs. 34, 35). Where the BSDF samples those numbers to the same direction (cosine directions on
 * a Lambertian surface), its sample is handed to the path, which continues along it. */
inline float3 estimate_emitter_along(const SceneView* scene, const SurfacePoint* sp, float3 w,
                                     float pdf_w, float2 u, bool by_cosine, uint* rays) {
    if (!(pdf_w > 0.0f) || w.z <= 0.0f) return (float3)(0.0f);
    Frame frame = frame_from_normal(sp->n);
    float3 wi = frame_to_world(&frame, w);
    SurfacePoint seen;
    bool found;
    BsdfSample bs;
    if (by_cosine && scene->continuation) bs = bsdf_sample(sp, u);
    if (by_cosine && scene->continuation && all(as_uint3(bs.wi) == as_uint3(wi)) &&
        bsdf_sample_is_direct(&bs))
        found = trace_bsdf_sample(scene, sp, &bs, rays, &seen);
    else
        found = trace_from(scene, sp, wi, rays, &seen);
    float3 Le = found ? emitted_radiance(&seen) : environment_radiance(scene, wi);
    return bsdf_eval(sp, wi) * Le * (w.z / pdf_w);
}

/* Directions uniform on the hemisphere, density 1/(2π) (eq. 34). */
inline float3 estimate_hemisphere_uniform(const SceneView* scene, const SurfacePoint* sp,
                                          const SampleStream* stream, uint* rays) {
    float2 u = sample_2d(stream, DIM_DIRECTION);
    float3 w = sample_hemisphere_uniform(u);
    return estimate_emitter_along(scene, sp, w, sample_hemisphere_uniform_pdf_w(w), u, false,
                                  rays);
}

/* Cosine-weighted directions, density cosθ/π (eq. 35). */
inline float3 estimate_hemisphere_cosine(const SceneView* scene, const SurfacePoint* sp,
                                         const SampleStream* stream, uint* rays) {
    float2 u = sample_2d(stream, DIM_DIRECTION);
    float3 w = sample_hemisphere_cosine(u);
    return estimate_emitter_along(scene, sp, w, sample_hemisphere_cosine_pdf_w(w), u, true,
                                  rays);
}

/* Directions by the BSDF's own sampling density (bsdf.cl: cosine on a Lambertian surface, the
 * density of hemisphere-cosine; GGX's visible normals for the specular lobe), counting the
 * emitters (and the sky light) they hit: the BSDF strategy of MIS alone (PBRT 3rd ed. 14.3.1). */
inline float3 estimate_bsdf(const SceneView* scene, const SurfacePoint* sp,
                            const SampleStream* stream, uint* rays) {
    BsdfSample bs = bsdf_sample(sp, sample_2d(stream, DIM_DIRECTION));
    if (!(bs.pdf_w > 0.0f) || bs.cos_theta <= 0.0f) return (float3)(0.0f);
    SurfacePoint seen;
    bool found = trace_bsdf_sample(scene, sp, &bs, rays, &seen);
    if (!bsdf_sample_is_direct(&bs)) return (float3)(0.0f); /* the path counts what it finds */
    float3 Le = found ? emitted_radiance(&seen) : environment_radiance(scene, bs.wi);
    return bs.f * Le * (bs.cos_theta / bs.pdf_w);
}

/* ---- Multiple importance sampling -------------------------------------------------------- */

/* One light-area sample and one BSDF sample, each weighted against the other's density
 * (Veach 1997, sec. 9.2; Mitsuba 3's `direct` integrator with one sample of each); a punctual
 * light's sample has weight 1, no BSDF sample finding it. */
inline float3 estimate_mis(const SceneView* scene, const SurfacePoint* sp,
                           const SampleStream* stream, uint* rays) {
    float3 L = (float3)(0.0f);

    /* Light strategy. */
    LightSample ls = sample_light_area(scene, sp, sample_2d(stream, DIM_LIGHT),
                                       sample_1d(stream, DIM_LIGHT_FINE));
    float cos_x = dot(sp->n, ls.wi);
    if (ls.valid && cos_x > 0.0f) {
        *rays += 1u;
        if (light_sample_visible(scene, sp, &ls)) {
            float pdf_light = light_sample_pdf_w(&ls);
            float pdf_bsdf = bsdf_pdf_w(sp, ls.wi);
            L += bsdf_eval(sp, ls.wi) * ls.Le *
                 (cos_x / pdf_light * light_sample_mis_weight(&ls, pdf_bsdf));
        }
    }

    /* BSDF strategy: the emitter its direction finds, if any, or the sky light. */
    BsdfSample bs = bsdf_sample(sp, sample_2d(stream, DIM_DIRECTION));
    SurfacePoint seen;
    if (bs.pdf_w > 0.0f && bs.cos_theta > 0.0f) {
        bool found = trace_bsdf_sample(scene, sp, &bs, rays, &seen);
        if (!bsdf_sample_is_direct(&bs)) {
            /* Through the surface or along a delta: the path counts what it finds. */
        } else if (found) {
            float3 Le = emitted_radiance(&seen);
            if (any(Le != (float3)(0.0f))) {
                float pdf_light = pdf_light_area(scene, sp, &seen, bs.wi);
                L += bs.f * Le * (bs.cos_theta / bs.pdf_w * mis_weight(bs.pdf_w, pdf_light));
            }
        } else if (scene->env.sky_pmf > 0.0f) {
            float pdf_light = pdf_light_sky(scene, sp, bs.wi);
            L += bs.f * environment_radiance(scene, bs.wi) *
                 (bs.cos_theta / bs.pdf_w * mis_weight(bs.pdf_w, pdf_light));
        }
    }
    return L;
}

/* ---- Ambient light ------------------------------------------------------------------------ */

/* albedo · L_sky · (1/π)∫ V(x, ω) cosθ dω for a direction w (local frame) of density pdf_w,
 * V from an any-hit ray (DESIGN.md). The ambient estimators keep the course's Lambertian albedo
 * whatever the BSDF. */
inline float3 estimate_sky_visibility(const SceneView* scene, const SurfacePoint* sp, float3 w,
                                      float pdf_w, uint* rays) {
    if (!(pdf_w > 0.0f) || w.z <= 0.0f) return (float3)(0.0f);
    Frame frame = frame_from_normal(sp->n);
    float t_max = scene->env.ao_distance > 0.0f ? scene->env.ao_distance : MAXFLOAT;
    float3 wi = frame_to_world(&frame, w);
    if (!escapes(scene, sp, wi, t_max, rays)) return (float3)(0.0f);
#if defined(MCRT_ENVIRONMENT_MAP)
    float3 L_sky = environment_radiance(scene, wi); /* the map as the sky */
#else
    float3 L_sky = scene->env.sky;
#endif
    return surface_albedo(sp) * L_sky * (MCRT_INV_PI * w.z / pdf_w);
}

inline float3 estimate_ambient_uniform(const SceneView* scene, const SurfacePoint* sp,
                                       const SampleStream* stream, uint* rays) {
    float3 w = sample_hemisphere_uniform(sample_2d(stream, DIM_DIRECTION));
    return estimate_sky_visibility(scene, sp, w, sample_hemisphere_uniform_pdf_w(w), rays);
}

inline float3 estimate_ambient_cosine(const SceneView* scene, const SurfacePoint* sp,
                                      const SampleStream* stream, uint* rays) {
    float3 w = sample_hemisphere_cosine(sample_2d(stream, DIM_DIRECTION));
    return estimate_sky_visibility(scene, sp, w, sample_hemisphere_cosine_pdf_w(w), rays);
}

/* Point `sample` of a spiral of sample_count points, rotated per pixel (perturbed spiral): each
 * point is uniform on the hemisphere, so the pixel mean is unbiased. */
inline float3 estimate_ambient_fibonacci(const SceneView* scene, const SurfacePoint* sp,
                                         const SampleStream* stream, uint* rays) {
    float3 w = sample_hemisphere_fibonacci(stream->sample, stream->sample_count,
                                           pixel_2d(stream, DIM_PIXEL_ROTATION));
    return estimate_sky_visibility(scene, sp, w, sample_hemisphere_fibonacci_pdf_w(w), rays);
}

#endif
