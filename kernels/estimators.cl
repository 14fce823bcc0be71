/* Estimators of the radiance reflected at a surface point toward the camera, chosen at compile
 * time with -D ESTIMATOR_... (DESIGN.md "Estimators"). Each takes its random numbers from the
 * shared stream layout of rng.cl, so two estimators can be compared on the same samples. */
#ifndef MCRT_ESTIMATORS_CL
#define MCRT_ESTIMATORS_CL

#include "frame.cl"
#include "rng.cl"
#include "scene.cl"

/* Below this solid angle (sr) spherical triangle sampling loses precision; above the maximum it
 * is near-degenerate too: such lights are sampled by area instead (as pbrt-v4 does). */
#define MIN_SPHERICAL_SOLID_ANGLE 3e-4f
#define MAX_SPHERICAL_SOLID_ANGLE 6.22f

typedef struct {
    float3 sky;        /* radiance of the uniform sky (ambient estimators) */
    float ao_distance; /* occlusion range; 0 = unbounded */
} Environment;

/* ---- Integrating over points on a light ------------------------------------------------- */

/* The random variable is (light, point) with density pmf(light)/area; the area measure becomes
 * solid angle through cosθ_y / d² (PBRT 3rd ed. 14.2.2; Veach 1997 eq. 8.4). */
inline float3 estimate_light_area(const SceneView* scene, const SurfacePoint* sp,
                                  const SampleStream* stream, uint* rays) {
    if (scene->lights.light_count == 0u) return (float3)(0.0f);
    DiscreteSample choice = select_light(&scene->lights, sample_1d(stream, DIM_LIGHT_SELECT));
    Light light = scene->lights.lights[choice.index];
    LightPoint lp = sample_light_point(&light, sample_2d(stream, DIM_LIGHT_POINT));

    float3 to_light = lp.p - sp->p;
    float d2 = dot(to_light, to_light);
    if (!(d2 > 0.0f)) return (float3)(0.0f);
    float3 wi = to_light * rsqrt(d2);
    float3 n_light = light_normal(&light);
    float cos_x = dot(sp->n, wi);
    float cos_y = light_emitting_cosine(&light, n_light, wi);
    /* Behind the receiver, or the light's back face: no contribution. */
    if (cos_x <= 0.0f || cos_y <= 0.0f) return (float3)(0.0f);

    *rays += 1u;
    float3 n_toward_x = dot(n_light, wi) < 0.0f ? n_light : -n_light;
    if (!visible(scene, sp->p, sp->n, lp.p, n_toward_x)) return (float3)(0.0f);
    float3 f = sp->material.albedo.xyz * MCRT_INV_PI;
    return f * light.Le.xyz * (cos_x * cos_y / (d2 * lp.pdf_a * choice.pmf));
}

/* ---- Integrating over the solid angle of a light ---------------------------------------- */

/* Directions uniform in the spherical triangle the chosen light subtends (Arvo 1995): density
 * pmf(light)/Ω, no 1/d² left in the estimate. Tiny or huge solid angles fall back to area
 * sampling, a choice fixed by (point, light), so the estimator stays unbiased. */
inline float3 estimate_light_solid_angle(const SceneView* scene, const SurfacePoint* sp,
                                         const SampleStream* stream, uint* rays) {
    if (scene->lights.light_count == 0u) return (float3)(0.0f);
    DiscreteSample choice = select_light(&scene->lights, sample_1d(stream, DIM_LIGHT_SELECT));
    Light light = scene->lights.lights[choice.index];
    float3 n_light = light_normal(&light);
    float3 x = sp->p;
    /* A one-sided light seen from behind its plane shows only its back. */
    if (!light_double_sided(&light) && dot(n_light, x - light.p0.xyz) <= 0.0f)
        return (float3)(0.0f);

    float3 a = normalize(light.p0.xyz - x), b = normalize(light.p1.xyz - x),
           c = normalize(light.p2.xyz - x);
    float omega = spherical_triangle_solid_angle(a, b, c);
    float2 u = sample_2d(stream, DIM_LIGHT_POINT);
    float3 wi, y;
    float pdf_w;
    if (omega > MIN_SPHERICAL_SOLID_ANGLE && omega < MAX_SPHERICAL_SOLID_ANGLE) {
        wi = sample_spherical_triangle_omega(a, b, c, omega, u);
        pdf_w = 1.0f / omega;
        /* Where the direction meets the light's plane. */
        float denom = dot(wi, n_light);
        float t = dot(light.p0.xyz - x, n_light) / denom;
        if (!(t > 0.0f) || !isfinite(t)) return (float3)(0.0f);
        y = x + t * wi;
    } else {
        LightPoint lp = sample_light_point(&light, u);
        float3 to_light = lp.p - x;
        float d2 = dot(to_light, to_light);
        if (!(d2 > 0.0f)) return (float3)(0.0f);
        wi = to_light * rsqrt(d2);
        float cos_y = light_emitting_cosine(&light, n_light, wi);
        if (cos_y <= 0.0f) return (float3)(0.0f);
        pdf_w = lp.pdf_a * d2 / cos_y;
        y = lp.p;
    }
    float cos_x = dot(sp->n, wi);
    if (cos_x <= 0.0f || light_emitting_cosine(&light, n_light, wi) <= 0.0f) return (float3)(0.0f);

    *rays += 1u;
    float3 n_toward_x = dot(n_light, wi) < 0.0f ? n_light : -n_light;
    if (!visible(scene, x, sp->n, y, n_toward_x)) return (float3)(0.0f);
    float3 f = sp->material.albedo.xyz * MCRT_INV_PI;
    return f * light.Le.xyz * (cos_x / (pdf_w * choice.pmf));
}

/* ---- Integrating over directions --------------------------------------------------------- */

/* A direction about the normal by the estimator's density (eq. 34 uniform, eq. 35 cosine). */
inline float3 sample_direction_local(const SampleStream* stream, float* pdf_w) {
    float2 u = sample_2d(stream, DIM_DIRECTION);
#if defined(ESTIMATOR_HEMISPHERE_UNIFORM) || defined(ESTIMATOR_AMBIENT_UNIFORM)
    float3 w = sample_hemisphere_uniform(u);
    *pdf_w = sample_hemisphere_uniform_pdf_w(w);
#elif defined(ESTIMATOR_AMBIENT_FIBONACCI)
    /* Point `sample` of a spiral of sample_count points, rotated per pixel (perturbed spiral):
     * each point is uniform on the hemisphere, so the pixel mean is unbiased. */
    float3 w = sample_hemisphere_fibonacci(stream->sample, stream->sample_count,
                                           pixel_2d(stream, DIM_PIXEL_ROTATION));
    *pdf_w = sample_hemisphere_fibonacci_pdf_w(w);
#else
    float3 w = sample_hemisphere_cosine(u);
    *pdf_w = sample_hemisphere_cosine_pdf_w(w);
#endif
    return w;
}

/* The emitter seen from sp along direction wi (unit, world): its radiance toward sp. */
inline float3 emitted_along(const SceneView* scene, const SurfacePoint* sp, float3 wi, uint* rays,
                            SurfacePoint* seen) {
    *rays += 1u;
    Ray r = make_ray(offset_ray_origin(sp->p, sp->n), wi);
    Hit hit = bvh_closest_hit(scene->nodes, scene->packets, &r, MAXFLOAT);
    if (hit.triangle == NO_HIT) return (float3)(0.0f);
    *seen = surface_point(scene, &r, &hit);
    return emitted_radiance(seen);
}

/* Directions hitting emitters: f·Le·cosθ / pdf(ω) (GI Compendium eqs. 34, 35). */
inline float3 estimate_hemisphere(const SceneView* scene, const SurfacePoint* sp,
                                  const SampleStream* stream, uint* rays) {
    float pdf_w;
    float3 w = sample_direction_local(stream, &pdf_w);
    if (!(pdf_w > 0.0f) || w.z <= 0.0f) return (float3)(0.0f);
    Frame frame = frame_from_normal(sp->n);
    SurfacePoint seen;
    float3 Le = emitted_along(scene, sp, frame_to_world(&frame, w), rays, &seen);
    return sp->material.albedo.xyz * MCRT_INV_PI * Le * (w.z / pdf_w);
}

/* ---- Multiple importance sampling -------------------------------------------------------- */

/* Weight of strategy a against b, both densities in solid angle (Veach 1997, sec. 9.2): balance,
 * or power with β = 2 (-D MIS_POWER), written as ratios so large densities cannot overflow. */
inline float mis_weight(float pdf_a, float pdf_b) {
    if (!(pdf_b > 0.0f)) return 1.0f;
    float r = pdf_b / pdf_a;
#if defined(MIS_POWER)
    return 1.0f / (1.0f + r * r);
#else
    return 1.0f / (1.0f + r);
#endif
}

/* One light-area sample and one cosine sample, each weighted against the other's density. */
inline float3 estimate_mis(const SceneView* scene, const SurfacePoint* sp,
                           const SampleStream* stream, uint* rays) {
    float3 f = sp->material.albedo.xyz * MCRT_INV_PI;
    Frame frame = frame_from_normal(sp->n);
    float3 L = (float3)(0.0f);

    /* Light strategy. */
    if (scene->lights.light_count > 0u) {
        DiscreteSample choice = select_light(&scene->lights, sample_1d(stream, DIM_LIGHT_SELECT));
        Light light = scene->lights.lights[choice.index];
        LightPoint lp = sample_light_point(&light, sample_2d(stream, DIM_LIGHT_POINT));
        float3 to_light = lp.p - sp->p;
        float d2 = dot(to_light, to_light);
        float3 wi = to_light * rsqrt(d2);
        float3 n_light = light_normal(&light);
        float cos_x = dot(sp->n, wi);
        float cos_y = light_emitting_cosine(&light, n_light, wi);
        if (d2 > 0.0f && cos_x > 0.0f && cos_y > 0.0f) {
            *rays += 1u;
            float3 n_toward_x = dot(n_light, wi) < 0.0f ? n_light : -n_light;
            if (visible(scene, sp->p, sp->n, lp.p, n_toward_x)) {
                float pdf_light = choice.pmf * lp.pdf_a * d2 / cos_y;
                float pdf_cosine = sample_hemisphere_cosine_pdf_w(frame_to_local(&frame, wi));
                L += f * light.Le.xyz * (cos_x / pdf_light * mis_weight(pdf_light, pdf_cosine));
            }
        }
    }

    /* Cosine strategy. */
    float3 w = sample_hemisphere_cosine(sample_2d(stream, DIM_DIRECTION));
    float pdf_cosine = sample_hemisphere_cosine_pdf_w(w);
    if (pdf_cosine > 0.0f && w.z > 0.0f) {
        float3 wi = frame_to_world(&frame, w);
        SurfacePoint seen;
        float3 Le = emitted_along(scene, sp, wi, rays, &seen);
        if (any(Le != (float3)(0.0f))) {
            /* The light strategy's density for the same direction, if the emitter is a light. */
            float pdf_light = 0.0f;
            if (seen.light != 0u && scene->lights.light_count > 0u) {
                Light light = scene->lights.lights[seen.light - 1u];
                float3 d = seen.p - sp->p;
                float cos_y = fabs(dot(seen.n, wi));
                pdf_light = light_pmf(&scene->lights, seen.light - 1u) * dot(d, d) /
                            (cos_y * light_area(&light));
            }
            L += f * Le * (w.z / pdf_cosine * mis_weight(pdf_cosine, pdf_light));
        }
    }
    return L;
}

/* ---- Ambient light ------------------------------------------------------------------------ */

/* albedo · L_sky · (1/π)∫ V(x, ω) cosθ dω with V from an any-hit ray (DESIGN.md). */
inline float3 estimate_ambient(const SceneView* scene, const SurfacePoint* sp,
                               const SampleStream* stream, const Environment* env, uint* rays) {
    float pdf_w;
    float3 w = sample_direction_local(stream, &pdf_w);
    if (!(pdf_w > 0.0f) || w.z <= 0.0f) return (float3)(0.0f);
    Frame frame = frame_from_normal(sp->n);
    Ray r = make_ray(offset_ray_origin(sp->p, sp->n), frame_to_world(&frame, w));
    *rays += 1u;
    float t_max = env->ao_distance > 0.0f ? env->ao_distance : MAXFLOAT;
    if (bvh_any_hit(scene->nodes, scene->packets, &r, t_max)) return (float3)(0.0f);
    return sp->material.albedo.xyz * env->sky * (MCRT_INV_PI * w.z / pdf_w);
}

/* ---- The pixel sample ---------------------------------------------------------------------- */

#if defined(ESTIMATOR_AMBIENT_UNIFORM) || defined(ESTIMATOR_AMBIENT_COSINE) || \
    defined(ESTIMATOR_AMBIENT_FIBONACCI)
#define ESTIMATOR_AMBIENT 1
#endif

/* Radiance arriving along a camera ray: Le at the first hit plus the estimate of reflected
 * light; a ray leaving the scene sees black, or the sky in ambient mode (DESIGN.md
 * "Radiometric contract"). Counts the rays traced in *rays. */
inline float3 radiance(const SceneView* scene, const Ray* r, const SampleStream* stream,
                       const Environment* env, uint* rays) {
    *rays += 1u;
    Hit hit = bvh_closest_hit(scene->nodes, scene->packets, r, MAXFLOAT);
#if defined(ESTIMATOR_AMBIENT)
    if (hit.triangle == NO_HIT) return env->sky;
#else
    if (hit.triangle == NO_HIT) return (float3)(0.0f);
#endif
    SurfacePoint sp = surface_point(scene, r, &hit);
    float3 L = emitted_radiance(&sp);
#if defined(ESTIMATOR_LIGHT_AREA)
    L += estimate_light_area(scene, &sp, stream, rays);
#elif defined(ESTIMATOR_LIGHT_SOLID_ANGLE)
    L += estimate_light_solid_angle(scene, &sp, stream, rays);
#elif defined(ESTIMATOR_HEMISPHERE_UNIFORM) || defined(ESTIMATOR_HEMISPHERE_COSINE)
    L += estimate_hemisphere(scene, &sp, stream, rays);
#elif defined(ESTIMATOR_MIS)
    L += estimate_mis(scene, &sp, stream, rays);
#elif defined(ESTIMATOR_AMBIENT)
    L += estimate_ambient(scene, &sp, stream, env, rays);
#else
#error "no estimator selected: compile with -D ESTIMATOR_..."
#endif
    return L;
}

#endif
