/* The light strategies: a light and a point (or direction) on it from two random numbers, with
 * the emitted radiance, the density in the sample's own measure and the selection pmf; and the
 * twins that give the density of a direction found otherwise (a BSDF sample that hit a light),
 * what MIS needs (pbrt-v4's SampleLi / PDF_Li). Estimators reach the lights only through these. */
#ifndef MCRT_LIGHT_SAMPLING_CL
#define MCRT_LIGHT_SAMPLING_CL

#include "frame.cl"
#include "lights.cl"
#include "sampling.cl"
#include "scene.cl"

/* Below this solid angle (sr) spherical triangle sampling loses precision; above the maximum it
 * is near-degenerate too: such lights are sampled by area instead (as pbrt-v4 does). */
#define MIN_SPHERICAL_SOLID_ANGLE 3e-4f
#define MAX_SPHERICAL_SOLID_ANGLE 6.22f

/* The measure a LightSample's pdf is expressed in. */
#define LIGHT_MEASURE_AREA 0u        /* per unit area of the light */
#define LIGHT_MEASURE_SOLID_ANGLE 1u /* per steradian seen from the shading point */
/* A delta light (punctual, -D MCRT_PUNCTUAL builds): one direction, no density. Its sample reads
 * as a point of the area measure with pdf 1 and cos_light 1, so that the area formulas give the
 * estimate f · Le · cosθ_x / (d² · pmf): POSITION, a point or spot light at y, Le its intensity
 * × the spot's falloff toward x; DIRECTION, a directional light, Le its irradiance, d2 1 and its
 * shadow ray going to infinity. No BSDF sample can find it, so its MIS weight is 1. */
#define LIGHT_MEASURE_DELTA_POSITION 2u
#define LIGHT_MEASURE_DELTA_DIRECTION 3u

typedef struct {
    float3 wi;       /* unit, from the shading point toward y */
    float3 y;        /* the sampled point on the light */
    float3 y_error;  /* per-component bound on y's distance from the light's plane */
    float3 n_toward; /* the light's geometric normal on the shading point's side (ray offset) */
    float3 Le;       /* radiance the light emits toward the shading point (a delta light: its
                        intensity × falloff, or irradiance: LIGHT_MEASURE_DELTA_*) */
    float pmf;       /* probability of having chosen this light */
    float pdf;       /* density of y given the light, in `measure` */
    float d2;        /* |y − x|² */
    float cos_light; /* cosine at the light between its emitting normal and −wi, > 0 */
    uint measure;    /* LIGHT_MEASURE_AREA, _SOLID_ANGLE or a delta light's _DELTA_* */
    uint light;      /* index of the chosen light; LIGHT_SKY for the sky */
    bool valid;      /* false: the sample adds nothing (no lights, a back face, degenerate) */
} LightSample;

inline LightSample no_light_sample(void) {
    LightSample ls;
    ls.wi = ls.y = ls.y_error = ls.n_toward = ls.Le = (float3)(0.0f);
    ls.pmf = ls.pdf = ls.d2 = ls.cos_light = 0.0f;
    ls.measure = LIGHT_MEASURE_AREA;
    ls.light = 0u;
    ls.valid = false;
    return ls;
}

/* LightSample.light of a direction toward the sky light. */
#define LIGHT_SKY 0xffffffffu

/* Radiance that light `light` emits at barycentrics b of its vertices 1 and 2: its Le, or where
 * its emission varies over it (textured builds, MATERIAL_TEXTURED) Le × the emissive texture
 * there, none in a MASK hole, × alpha on a BLEND surface (which a ray hits with probability
 * alpha: the same expectation). */
inline float3 light_emission(const SceneView* scene, const Light* light, float2 b) {
#if defined(MCRT_TEXTURES)
    if (light->flags & MATERIAL_TEXTURED) {
        const TextureView* tv = &scene->textures;
        global const MaterialTextures* mt = material_textures(tv, light->material);
        float4 uv = surface_uv(tv, light->surface, b.x, b.y);
        float3 Le = light->Le.xyz;
        if (texture_slot_used(&mt->emissive)) Le *= texture_lookup(tv, &mt->emissive, uv).xyz;
        if (mt->alpha_mode == MATERIAL_ALPHA_MASK) {
            if (!(material_alpha(tv, mt, uv) >= mt->alpha_cutoff)) Le = (float3)(0.0f);
        } else if (mt->alpha_mode == MATERIAL_ALPHA_BLEND) {
            Le *= material_alpha(tv, mt, uv);
        }
        return Le;
    }
#endif
    return light->Le.xyz;
}

/* ---- The sky beside the area lights ---------------------------------------------------------- */

/* Chooses between the sky light, with probability env.sky_pmf, and the area lights, as pbrt-v4
 * keeps infinite lights beside its light sampler (BVHLightSampler's pInfinite). sky_pmf is 0, 1/2
 * (sky and area lights) or 1 (the sky alone), so the split of u on its 2^-24 grid is exact: true
 * for the sky, *u remapped uniform for its direction; false for the area lights, *u and *u_fine
 * remapped so that the light selection reads them as before, with probability 1 − sky_pmf. */
inline bool select_sky(const SceneView* scene, float* u, float* u_fine) {
    float sky_pmf = scene->env.sky_pmf;
    if (!(sky_pmf > 0.0f)) return false;
    if (sky_pmf >= 1.0f) return true;
    uint k = unit_to_grid(*u), lower = 0x800000u; /* the lower half of the grid */
    if (k < lower) {
        *u = remap_run(k, 0u, lower, *u_fine);
        return true;
    }
    /* The upper half's k − lower has 23 bits: u_fine's first bit is the 24th, the rest its fine. */
    uint bit = *u_fine >= 0.5f ? 1u : 0u;
    *u = (float)(2u * (k - lower) + bit) * 0x1.0p-24f;
    *u_fine = 2.0f * *u_fine - (float)bit;
    return false;
}

#if defined(MCRT_ENVIRONMENT_MAP)
/* Chooses between the environment map, with probability env.sky_pmf = m·2^-24 for a whole m
 * (the host's environment_pmf_steps), and the area lights, as select_sky does for any m: k, the
 * grid value of *u, below m chooses the map. The position within the chosen run of m (or 2^24 − m)
 * grid values, (k − first + u_fine)/count, is read back onto the grid as k' and u_fine' in integer
 * arithmetic: K = (k − first)·2^24 + ⌊u_fine·2^24⌋ takes each of its count·2^24 values with equal
 * probability, so k' = ⌊K/count⌋ is exactly uniform on the grid and u_fine' = (K mod count + ½)/count
 * refines it. */
inline bool select_environment(const SceneView* scene, float* u, float* u_fine) {
    uint m = (uint)(scene->env.sky_pmf * 16777216.0f);
    if (m == 0u) return false;
    if (m >= 0x1000000u) return true; /* the map alone: u and u_fine as they are */
    uint k = unit_to_grid(*u);
    bool env = k < m;
    uint first = env ? 0u : m, count = env ? m : 0x1000000u - m;
    ulong K = ((ulong)(k - first) << 24) | (ulong)unit_to_grid(*u_fine);
    *u = (float)(uint)(K / count) * 0x1.0p-24f;
    *u_fine = fmin(((float)(uint)(K % count) + 0.5f) / (float)count, 0x1.fffffep-1f);
    return env;
}
#endif

/* Probability that the light strategies choose among the area lights. */
inline float area_lights_pmf(const SceneView* scene) { return 1.0f - scene->env.sky_pmf; }

/* A direction toward the sky: cosine-weighted about the normal (the sky's radiance is uniform,
 * so this is the importance of a Lambertian receiver; GI Compendium eq. 35), in solid angle. */
inline LightSample sample_light_sky(const SceneView* scene, const SurfacePoint* sp, float2 u) {
    LightSample ls = no_light_sample();
    float3 w = sample_hemisphere_cosine(u);
    float pdf_w = sample_hemisphere_cosine_pdf_w(w);
    if (!(pdf_w > 0.0f)) return ls;
    Frame frame = frame_from_normal(sp->n);
    ls.wi = frame_to_world(&frame, w);
    ls.y = sp->p + ls.wi;
    ls.n_toward = -ls.wi;
    ls.Le = scene->env.sky;
    ls.pmf = scene->env.sky_pmf;
    ls.pdf = pdf_w;
    ls.d2 = 1.0f;
    ls.cos_light = 1.0f;
    ls.measure = LIGHT_MEASURE_SOLID_ANGLE;
    ls.light = LIGHT_SKY;
    ls.valid = true;
    return ls;
}

/* An area density converted to solid angle at distance² d2 and light cosine cos_light
 * (PBRT 3rd ed. 14.2.2; Veach 1997 eq. 8.4). */
inline float pdf_area_to_solid_angle(float pdf_a, float d2, float cos_light) {
    return pdf_a * d2 / cos_light;
}

/* Solid-angle density of the area strategy, the light's selection pmf included: the one form
 * that its sampler and its twin both use. */
inline float light_area_pdf_w(float pmf, float pdf_a, float d2, float cos_light) {
    return pmf * pdf_a * d2 / cos_light;
}

/* ---- Choosing the light: one routine for both strategies, and its twin --------------------- */

/* The light both strategies sample: the sky (select_sky) or an area light by the selection,
 * from u.x and u_fine, with u.x remapped uniform for the point or direction on it. */
typedef struct {
    Light light;   /* the area light chosen, when `area` */
    float pmf;     /* probability of the choice, the split with the sky included */
    float2 u;      /* the rest of the sample, uniform again */
    float u_fine;  /* u.x's refinement below the 2^-24 grid, for the environment map's texel */
    uint index;    /* the area light's index (a punctual light's: light_count + its own) */
    bool sky;      /* the sky light was chosen */
    bool area;     /* an area light was chosen; neither: nothing can be sampled */
    bool punctual; /* a punctual light was chosen (-D MCRT_PUNCTUAL builds) */
} LightChoice;

inline LightChoice choose_light(const SceneView* scene, const SurfacePoint* sp, float2 u,
                                float u_fine) {
    LightChoice c;
    c.sky = c.area = c.punctual = false;
    c.pmf = 0.0f;
    c.u_fine = 0.0f;
    c.index = 0u;
    float u_select = u.x; /* a vector's element has no address in OpenCL C */
#if defined(MCRT_ENVIRONMENT_MAP)
    if (select_environment(scene, &u_select, &u_fine)) {
        c.sky = true;
        c.u = (float2)(u_select, u.y);
        c.u_fine = u_fine;
        return c;
    }
#else
    if (select_sky(scene, &u_select, &u_fine)) {
        c.sky = true;
        c.u = (float2)(u_select, u.y);
        return c;
    }
#endif
    c.u = (float2)(u_select, u.y);
    if (light_selection_count(&scene->lights) == 0u) return c;
    DiscreteSample choice = select_light(&scene->lights, sp->p, sp->n, u_select, u_fine);
    if (!(choice.pmf > 0.0f)) return c; /* no light can reach sp (the tree) */
#if defined(MCRT_PUNCTUAL)
    if (choice.index >= scene->lights.light_count) { /* a delta light: nothing more to draw */
        c.pmf = choice.pmf * area_lights_pmf(scene);
        c.index = choice.index;
        c.punctual = true;
        return c;
    }
#endif
    c.light = scene->lights.lights[choice.index];
    c.pmf = choice.pmf * area_lights_pmf(scene);
    c.u = (float2)(choice.u_remap, u.y);
    c.index = choice.index;
    c.area = true;
    return c;
}

/* The twin: probability that choose_light at sp returns area light `index`. */
inline float chosen_light_pmf(const SceneView* scene, const SurfacePoint* sp, uint index) {
    return light_pmf(&scene->lights, sp->p, sp->n, index) * area_lights_pmf(scene);
}

#if defined(MCRT_ENVIRONMENT_MAP)
/* A direction toward the environment map by its texel distribution (environment.cl): c.u.x with
 * c.u_fine chooses the texel, its remapped number and c.u.y the direction within it; density in
 * solid angle, the map's pmf in the selection. */
inline LightSample sample_light_environment(const SceneView* scene, const SurfacePoint* sp,
                                            const LightChoice* c) {
    LightSample ls = no_light_sample();
    const EnvironmentMapView* env = &scene->env.map;
    EnvironmentSample es = sample_environment_map_reusing(env, c->u.x, c->u_fine, c->u.y);
    if (!(es.pdf_w > 0.0f)) return ls;
    ls.wi = es.wi;
    ls.y = sp->p + ls.wi;
    ls.n_toward = -ls.wi;
    ls.Le = (float3)(env->rgb[3u * es.texel], env->rgb[3u * es.texel + 1u],
                     env->rgb[3u * es.texel + 2u]);
    ls.pmf = scene->env.sky_pmf;
    ls.pdf = es.pdf_w;
    ls.d2 = 1.0f;
    ls.cos_light = 1.0f;
    ls.measure = LIGHT_MEASURE_SOLID_ANGLE;
    ls.light = LIGHT_SKY;
    ls.valid = true;
    return ls;
}
#define MCRT_SAMPLE_SKY_LIGHT(scene, sp, choice) sample_light_environment(scene, sp, &(choice))
#else
#define MCRT_SAMPLE_SKY_LIGHT(scene, sp, choice) sample_light_sky(scene, sp, (choice).u)
#endif

#if defined(MCRT_PUNCTUAL)
/* ---- Punctual lights: the one direction a delta light arrives from -------------------------- */

/* What the chosen punctual light sends to sp: a point or spot light's intensity × the spot's
 * falloff from its position, at distance² d2 (KHR_lights_punctual's implementation notes), a
 * directional light's irradiance from the direction opposite to where it points. Both strategies
 * sample it alike, with the selection's pmf as the sample's only probability (PBRT 4th ed. 12.1,
 * 12.4). */
inline LightSample sample_light_punctual(const SceneView* scene, const SurfacePoint* sp,
                                         const LightChoice* choice) {
    LightSample ls = no_light_sample();
    global const PunctualGpu* light =
        scene->lights.punctual + (choice->index - scene->lights.light_count);
    float3 I = light->intensity.xyz;
    if (light->type == PUNCTUAL_DIRECTIONAL) {
        ls.wi = -light->direction.xyz;
        ls.y = sp->p + ls.wi;
        ls.Le = I;
        ls.d2 = 1.0f;
        ls.measure = LIGHT_MEASURE_DELTA_DIRECTION;
    } else {
        float3 to_light = light->position.xyz - sp->p;
        float d2 = dot(to_light, to_light);
        if (!(d2 > 0.0f)) return ls;
        float3 wi = to_light * (1.0f / sqrt(d2));
        /* clamp(cos θ · scale + offset, 0, 1)², θ from the spot's axis; 1 for a point light. */
        float t = clamp(-dot(wi, light->direction.xyz) * light->spot_scale + light->spot_offset,
                        0.0f, 1.0f);
        float falloff = t * t;
        if (!(falloff > 0.0f)) return ls; /* outside the spot's cone */
        ls.wi = wi;
        ls.y = light->position.xyz;
        ls.Le = I * falloff;
        ls.d2 = d2;
        ls.measure = LIGHT_MEASURE_DELTA_POSITION;
    }
    ls.n_toward = -ls.wi;
    ls.pmf = choice->pmf;
    ls.pdf = 1.0f;
    ls.cos_light = 1.0f;
    ls.light = choice->index;
    ls.valid = true;
    return ls;
}
#endif

/* ---- Area strategy: (light, point) with density pmf(light)/area ------------------------------ */

inline LightSample sample_light_area(const SceneView* scene, const SurfacePoint* sp, float2 u,
                                     float u_fine) {
    LightChoice choice = choose_light(scene, sp, u, u_fine);
    if (choice.sky) return MCRT_SAMPLE_SKY_LIGHT(scene, sp, choice);
#if defined(MCRT_PUNCTUAL)
    if (choice.punctual) return sample_light_punctual(scene, sp, &choice);
#endif
    LightSample ls = no_light_sample();
    if (!choice.area) return ls;
    const Light light = choice.light;
    LightPoint lp = sample_light_point(&light, choice.u);
    float3 to_light = lp.p - sp->p;
    float d2 = dot(to_light, to_light);
    if (!(d2 > 0.0f)) return ls;
    float3 wi = to_light * (1.0f / sqrt(d2));
    float3 n_light = light_normal(&light);
    float cos_y = light_emitting_cosine(&light, n_light, wi);
    if (cos_y <= 0.0f) return ls; /* the light's back face */
    ls.wi = wi;
    ls.y = lp.p;
    ls.y_error = lp.p_error;
    ls.n_toward = dot(n_light, wi) < 0.0f ? n_light : -n_light;
    ls.Le = light_emission(scene, &light, lp.b);
    ls.pmf = choice.pmf;
    ls.pdf = lp.pdf_a;
    ls.d2 = d2;
    ls.cos_light = cos_y;
    ls.measure = LIGHT_MEASURE_AREA;
    ls.light = choice.index;
    ls.valid = true;
    return ls;
}

/* ---- Solid-angle strategy: directions uniform in the light's spherical triangle (Arvo 1995) -- */

/* Density pmf(light)/Ω, no 1/d² left in the estimate. Tiny or huge solid angles fall back to
 * area sampling, a choice fixed by (point, light), so the estimator stays unbiased. */
inline LightSample sample_light_solid_angle(const SceneView* scene, const SurfacePoint* sp,
                                            float2 u_light, float u_fine) {
    LightChoice choice = choose_light(scene, sp, u_light, u_fine);
    if (choice.sky) return MCRT_SAMPLE_SKY_LIGHT(scene, sp, choice);
#if defined(MCRT_PUNCTUAL)
    if (choice.punctual) return sample_light_punctual(scene, sp, &choice);
#endif
    LightSample ls = no_light_sample();
    if (!choice.area) return ls;
    const Light light = choice.light;
    float2 u = choice.u; /* the rest of the sample, for the direction */
    float3 n_light = light_normal(&light);
    float3 x = sp->p;
    /* A one-sided light seen from behind its plane shows only its back. */
    if (!light_double_sided(&light) && dot(n_light, x - light.p0.xyz) <= 0.0f) return ls;

    float3 a = normalize(light.p0.xyz - x), b = normalize(light.p1.xyz - x),
           c = normalize(light.p2.xyz - x);
    float omega = spherical_triangle_solid_angle(a, b, c);
    float3 wi, y, y_error;
    float2 b_y; /* y's barycentrics */
    float pdf_w;
    if (omega > MIN_SPHERICAL_SOLID_ANGLE && omega < MAX_SPHERICAL_SOLID_ANGLE) {
        wi = sample_spherical_triangle_omega(a, b, c, omega, u);
        pdf_w = 1.0f / omega;
        /* Where the direction meets the light's plane. */
        float3 to_p0 = light.p0.xyz - x;
        float denom = dot(wi, n_light);
        float t = dot(to_p0, n_light) / denom;
        if (!(t > 0.0f) || !isfinite(t)) return ls;
        float3 t_wi = t * wi;
        y = x + t_wi;
        /* y's distance from the plane: the numerator's rounding (γ(4)·|p0 − x|·|n|) and the
         * denominator's (γ(3)·|t·wi|·|n|) reach it through t·denom, the last sum's two roundings
         * add γ(2)·(|x| + |t·wi|), and the normal's own rounding tilts the plane about p0 by
         * γ(4)·|y − p0|, bounded by |p0 − x| + |t·wi|. */
        y_error = MCRT_GAMMA(8) * (fabs(x) + fabs(t_wi) + fabs(to_p0));
#if defined(MCRT_TEXTURES)
        b_y = light_barycentrics(&light, y);
#else
        b_y = (float2)(0.0f);
#endif
    } else {
        LightPoint lp = sample_light_point(&light, u);
        float3 to_light = lp.p - x;
        float d2 = dot(to_light, to_light);
        if (!(d2 > 0.0f)) return ls;
        wi = to_light * (1.0f / sqrt(d2));
        float cos_y = light_emitting_cosine(&light, n_light, wi);
        if (cos_y <= 0.0f) return ls;
        pdf_w = pdf_area_to_solid_angle(lp.pdf_a, d2, cos_y);
        y = lp.p;
        y_error = lp.p_error;
        b_y = lp.b;
    }
    float cos_y = light_emitting_cosine(&light, n_light, wi);
    if (cos_y <= 0.0f) return ls;
    float3 d = y - x;
    ls.wi = wi;
    ls.y = y;
    ls.y_error = y_error;
    ls.n_toward = dot(n_light, wi) < 0.0f ? n_light : -n_light;
    ls.Le = light_emission(scene, &light, b_y);
    ls.pmf = choice.pmf;
    ls.pdf = pdf_w;
    ls.d2 = dot(d, d);
    ls.cos_light = cos_y;
    ls.measure = LIGHT_MEASURE_SOLID_ANGLE;
    ls.light = choice.index;
    ls.valid = true;
    return ls;
}

/* ---- Using a light sample ----------------------------------------------------------------------
 */

/* True when the sample's pdf is per unit area: an area light's, and a delta light's, which reads
 * as a point of pdf 1 (LIGHT_MEASURE_DELTA_*). */
inline bool light_sample_per_area(const LightSample* ls) {
#if defined(MCRT_PUNCTUAL)
    return ls->measure != LIGHT_MEASURE_SOLID_ANGLE;
#else
    return ls->measure == LIGHT_MEASURE_AREA;
#endif
}

/* cosθ_x · G / density, in the sample's own measure: cosθ_x cosθ_y / (d² pdf_a pmf) per area
 * (a delta light: cosθ_x / (d² pmf)), cosθ_x / (pdf_w pmf) per solid angle, so that
 * f · Le · weight is the estimate. */
inline float light_sample_weight(const LightSample* ls, float cos_x) {
    if (light_sample_per_area(ls))
        return cos_x * ls->cos_light / (ls->d2 * ls->pdf * ls->pmf);
    return cos_x / (ls->pdf * ls->pmf);
}

/* True for a delta light's sample (punctual lights): no BSDF sample can find it, its MIS weight
 * is 1, and light_sample_pdf_w is no density (pmf · d²). */
inline bool light_sample_is_delta(const LightSample* ls) {
#if defined(MCRT_PUNCTUAL)
    return ls->measure >= LIGHT_MEASURE_DELTA_POSITION;
#else
    return false;
#endif
}

/* Density of the sample's direction with respect to solid angle, the selection included (a
 * delta light has none: pmf · d², which Le / it turns into what arrives; light_sample_is_delta). */
inline float light_sample_pdf_w(const LightSample* ls) {
    if (light_sample_per_area(ls))
        return light_area_pdf_w(ls->pmf, ls->pdf, ls->d2, ls->cos_light);
    return ls->pdf * ls->pmf;
}

/* True if nothing blocks the segment from the shading point to the light sample. */
inline bool light_sample_visible(const SceneView* scene, const SurfacePoint* sp,
                                 const LightSample* ls) {
    bool at_infinity = ls->light == LIGHT_SKY;
#if defined(MCRT_PUNCTUAL)
    at_infinity = at_infinity || ls->measure == LIGHT_MEASURE_DELTA_DIRECTION;
#endif
    if (at_infinity) { /* nothing along the ray to infinity */
        Ray r = make_ray(spawn_origin(sp), ls->wi);
        AlphaTest at = ray_alpha_test(scene, &r);
        return !bvh_any_hit(scene->nodes, scene->packets, &r, MAXFLOAT, sp->lane, &at);
    }
    return visible(scene, sp, ls->y, ls->y_error, ls->n_toward);
}

/* ---- The twins: densities of a direction wi from sp that hit the light at `seen` ------------- */

/* Density with respect to solid angle with which sample_light_area would have chosen wi; 0 when
 * `seen` is not a light. */
inline float pdf_light_area(const SceneView* scene, const SurfacePoint* sp,
                            const SurfacePoint* seen, float3 wi) {
    if (seen->light == 0u || scene->lights.light_count == 0u) return 0.0f;
    uint index = seen->light - 1u;
    Light light = scene->lights.lights[index];
    float3 d = seen->p - sp->p;
    float cos_y = fabs(dot(seen->ng, wi));
    float pmf = chosen_light_pmf(scene, sp, index);
    return light_area_pdf_w(pmf, sample_triangle_uniform_pdf_a(light_area(&light)), dot(d, d),
                            cos_y);
}

/* Density with respect to solid angle with which sample_light_solid_angle would have chosen wi;
 * 0 when `seen` is not a light or shows its back. */
inline float pdf_light_solid_angle(const SceneView* scene, const SurfacePoint* sp,
                                   const SurfacePoint* seen, float3 wi) {
    if (seen->light == 0u || scene->lights.light_count == 0u) return 0.0f;
    uint index = seen->light - 1u;
    Light light = scene->lights.lights[index];
    float3 n_light = light_normal(&light);
    float3 x = sp->p;
    if (!light_double_sided(&light) && dot(n_light, x - light.p0.xyz) <= 0.0f) return 0.0f;
    float cos_y = light_emitting_cosine(&light, n_light, wi);
    if (cos_y <= 0.0f) return 0.0f;
    float3 a = normalize(light.p0.xyz - x), b = normalize(light.p1.xyz - x),
           c = normalize(light.p2.xyz - x);
    float omega = spherical_triangle_solid_angle(a, b, c);
    float pmf = chosen_light_pmf(scene, sp, index);
    if (omega > MIN_SPHERICAL_SOLID_ANGLE && omega < MAX_SPHERICAL_SOLID_ANGLE) return pmf / omega;
    float3 d = seen->p - x;
    return pmf * pdf_area_to_solid_angle(sample_triangle_uniform_pdf_a(light_area(&light)),
                                         dot(d, d), cos_y);
}

/* Density with respect to solid angle with which either light strategy chooses the sky direction
 * wi (unit, world) from sp, the twin of sample_light_sky with the sky's pmf; 0 when the sky is
 * no light. */
inline float pdf_light_sky(const SceneView* scene, const SurfacePoint* sp, float3 wi) {
    if (!(scene->env.sky_pmf > 0.0f)) return 0.0f;
#if defined(MCRT_ENVIRONMENT_MAP)
    return scene->env.sky_pmf * environment_map_pdf_w(&scene->env.map, wi);
#else
    Frame frame = frame_from_normal(sp->n);
    return scene->env.sky_pmf * sample_hemisphere_cosine_pdf_w(frame_to_local(&frame, wi));
#endif
}

#endif
