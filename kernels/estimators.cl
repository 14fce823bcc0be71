/* Estimators of the reflected direct radiance at a surface point. */
#ifndef MCRT_ESTIMATORS_CL
#define MCRT_ESTIMATORS_CL

#include "rng.cl"
#include "scene.cl"

/* Integrating over points on a chosen light: the random variable is (light, point), with density
 * pmf(light) / area; the area measure turns into solid angle through cosθ_y / d²
 * (PBRT 3rd ed. 14.2.2, "Sampling Light Sources"; Veach 1997 eq. 8.4). */
inline float3 estimate_light_area(const SceneView* scene, const SurfacePoint* sp,
                                  const SampleStream* stream, uint* rays) {
    if (scene->lights.light_count == 0u) return (float3)(0.0f);
    LightChoice choice = select_light(&scene->lights, sample_1d(stream, DIM_LIGHT_SELECT));
    Light light = scene->lights.lights[choice.index];
    LightPoint lp = sample_light_point(&light, sample_2d(stream, DIM_LIGHT_POINT));

    float3 to_light = lp.p - sp->p;
    float d2 = dot(to_light, to_light);
    if (!(d2 > 0.0f)) return (float3)(0.0f);
    float3 wi = to_light * rsqrt(d2);
    float cos_x = dot(sp->n, wi);
    float cos_y = -dot(lp.n, wi);
    if (light_double_sided(&light)) cos_y = fabs(cos_y);
    /* Behind the receiver, or the light's back face: no contribution. */
    if (cos_x <= 0.0f || cos_y <= 0.0f) return (float3)(0.0f);

    float3 n_light_toward_x = dot(lp.n, wi) < 0.0f ? lp.n : -lp.n;
    *rays += 1u;
    if (!visible(scene, sp->p, sp->n, lp.p, n_light_toward_x)) return (float3)(0.0f);

    float3 f = sp->material.albedo.xyz * MCRT_INV_PI;
    return f * light.Le.xyz * (cos_x * cos_y / (d2 * lp.pdf_a * choice.pmf));
}

/* Radiance arriving along a camera ray: Le at the first hit plus reflected direct light
 * (DESIGN.md "Radiometric contract"). Counts the rays traced in *rays. */
inline float3 radiance(const SceneView* scene, const Ray* r, const SampleStream* stream,
                       uint* rays) {
    *rays += 1u;
    Hit hit = bvh_closest_hit(scene->nodes, scene->triangles, r, MAXFLOAT);
    if (hit.triangle == NO_HIT) return (float3)(0.0f);
    SurfacePoint sp = surface_point(scene, r, &hit);
    float3 L = emitted_radiance(&sp);
#if defined(ESTIMATOR_LIGHT_AREA)
    L += estimate_light_area(scene, &sp, stream, rays);
#else
#error "no estimator selected: compile with -D ESTIMATOR_..."
#endif
    return L;
}

#endif
