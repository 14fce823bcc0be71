/* The course's last question, as a user's estimator: choose the light in proportion to its
 * estimated contribution at the shading point, not to its power.
 *
 *     mcrt render scenes/stress/light-facing-away.gltf --out a.exr \
 *         --estimator-file examples/estimators/light_contribution.cl
 *
 * Each light i gets the importance
 *
 *     w_i = lum(Le_i) · area_i · max(cosθ_x, c) · max(cosθ_y, c) / max(d², area_i)
 *
 * at its centroid (c = 0.05 keeps the estimate of a poorly seen light from collapsing), and
 * w_i = 0 exactly when the light cannot contribute at all: its emitting side faces away from
 * the shading point, or all three corners lie below the shading point's horizon (n · (y − x) is
 * linear in y, so then every point of the triangle does). Every light that can contribute has
 * w_i > 0, so the estimator is unbiased whatever the weights' quality. The light is chosen by
 * walking the weights with u · Σw (two passes over the lights: O(lights) per sample, for scenes
 * of tens to hundreds of lights — a light tree does it in O(log lights)); pmf = w_i / Σw; the
 * point is uniform on the light, as in light-area, from the same 2D sample: its x, remapped
 * within the chosen light's share of [0, 1), and its y. The random numbers are light-area's
 * (DIM_LIGHT): the two compare on common random numbers. Under --sky the sky light is chosen
 * first with light-area's probability, from the lower part of the same x. */

#define CONTRIBUTION_COSINE_FLOOR 0.05f

inline float luminance(float3 c) { return dot(c, (float3)(0.2126f, 0.7152f, 0.0722f)); }

/* The importance w_i of light i at the shading point (0: it cannot contribute there). */
inline float light_importance(const SurfacePoint* sp, const Light* light) {
    float3 p0 = light->p0.xyz, p1 = light->p1.xyz, p2 = light->p2.xyz;
    float3 n_light = light_normal(light);
    float facing = dot(n_light, sp->p - p0); /* > 0: sp is on the front side */
    if (!light_double_sided(light) && facing <= 0.0f) return 0.0f;
    float above =
        fmax(dot(sp->n, p0 - sp->p), fmax(dot(sp->n, p1 - sp->p), dot(sp->n, p2 - sp->p)));
    if (!(above > 0.0f)) return 0.0f;

    float3 to_centroid = (p0 + p1 + p2) * (1.0f / 3.0f) - sp->p;
    float d2 = dot(to_centroid, to_centroid);
    float area = light_area(light);
    float inv_d = d2 > 0.0f ? rsqrt(d2) : 0.0f;
    float cos_x = fmax(dot(sp->n, to_centroid) * inv_d, CONTRIBUTION_COSINE_FLOOR);
    float cos_y = fmax(fabs(facing) * inv_d, CONTRIBUTION_COSINE_FLOOR);
    return luminance(light->Le.xyz) * area * cos_x * cos_y / fmax(d2, area);
}

float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream,
                uint* rays) {
    float2 u = sample_2d(stream, DIM_LIGHT);
    /* The sky light of --sky is one more light, chosen with the probability the built-in light
     * strategies give it (scene->env.sky_pmf: 1/2 beside area lights, 1 alone; 0 without --sky,
     * when nothing here changes), its direction cosine-weighted about the normal. */
    float sky_pmf = scene->env.sky_pmf;
    if (sky_pmf > 0.0f && u.x < sky_pmf) {
        float3 w = sample_hemisphere_cosine((float2)(fmin(u.x / sky_pmf, 0x1.fffffep-1f), u.y));
        float pdf_w = sample_hemisphere_cosine_pdf_w(w);
        if (!(pdf_w > 0.0f)) return (float3)(0.0f);
        Frame frame = frame_from_normal(sp->n);
        float3 wi = frame_to_world(&frame, w);
        if (!escapes(scene, sp, wi, MAXFLOAT, rays)) return (float3)(0.0f);
        return bsdf_eval(sp, wi) * scene->env.sky * (w.z / (pdf_w * sky_pmf));
    }
    if (sky_pmf > 0.0f) u.x = fmin((u.x - sky_pmf) / (1.0f - sky_pmf), 0x1.fffffep-1f);

    uint n = scene->lights.light_count;
    if (n == 0u) return (float3)(0.0f);

    /* Light selection by estimated contribution: the total, then the walk. */
    float total = 0.0f;
    for (uint i = 0u; i < n; ++i) {
        Light light = scene->lights.lights[i];
        total += light_importance(sp, &light);
    }
    if (!(total > 0.0f)) return (float3)(0.0f); /* no light can reach this point */
    float target = u.x * total;
    uint chosen = n;
    float w_chosen = 0.0f, running = 0.0f, start = 0.0f;
    for (uint i = 0u; i < n; ++i) {
        Light light = scene->lights.lights[i];
        float w = light_importance(sp, &light);
        if (w <= 0.0f) continue;
        chosen = i; /* the last light with weight, should rounding leave target beyond the sum */
        w_chosen = w;
        start = running;
        running += w;
        if (target < running) break;
    }
    float pmf = w_chosen / total * (1.0f - sky_pmf); /* the area lights share 1 − sky_pmf */
    /* Where target fell in the chosen light's share, rescaled: uniform again, for the point. */
    float u_remap = clamp((target - start) / w_chosen, 0.0f, 0x1.fffffep-1f);

    /* A uniform point on the chosen light (density 1/area), as light-area. */
    Light light = scene->lights.lights[chosen];
    LightPoint lp = sample_light_point(&light, (float2)(u_remap, u.y));
    float3 to_light = lp.p - sp->p;
    float d2 = dot(to_light, to_light);
    if (!(d2 > 0.0f)) return (float3)(0.0f);
    float3 wi = to_light * rsqrt(d2);
    float3 n_light = light_normal(&light);
    float cos_x = dot(sp->n, wi);
    float cos_y = light_emitting_cosine(&light, n_light, wi);
    if (cos_x <= 0.0f || cos_y <= 0.0f) return (float3)(0.0f);

    *rays += 1u;
    float3 n_toward_x = dot(n_light, wi) < 0.0f ? n_light : -n_light;
    if (!visible(scene, sp, lp.p, lp.p_error, n_toward_x)) return (float3)(0.0f);
    return bsdf_eval(sp, wi) * light.Le.xyz * (cos_x * cos_y / (d2 * lp.pdf_a * pmf));
}
