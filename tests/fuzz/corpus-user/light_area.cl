/* The built-in `light-area` estimator written as a user's estimator file, through the public
 * kernel API only (docs/ESTIMATORS.md):
 *
 *     mcrt render scenes/cornell/CornellBox-Original.gltf --out a.exr \
 *         --estimator-file examples/estimators/light_area.cl
 *
 * renders the image of `--estimator light-area`, bit for bit, with any sampler and light
 * selection: the same random numbers (DIM_LIGHT, DIM_LIGHT_FINE) and the same arithmetic.
 *
 * The random variable is (light, point on it): the light with probability pmf (--light-select),
 * the point uniform on its area (density pdf_a = 1/area). The estimate of the reflected radiance
 * is f · Le · cosθ_x · cosθ_y / (d² · pdf_a · pmf), cosθ_y / d² turning the area measure into
 * solid angle (PBRT 3rd ed. 14.2.2; Veach 1997 eq. 8.4). */

float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream,
                uint* rays) {
    /* Light strategy: a light, a point on it; invalid when there is no light or its back
     * faces the shading point. */
    LightSample ls = sample_light_area(scene, sp, sample_2d(stream, DIM_LIGHT),
                                       sample_1d(stream, DIM_LIGHT_FINE));
    float cos_x = dot(sp->n, ls.wi);
    if (!ls.valid || cos_x <= 0.0f) return (float3)(0.0f); /* below the shading point's horizon */

    /* Visibility: one shadow ray, counted. */
    *rays += 1u;
    if (!light_sample_visible(scene, sp, &ls)) return (float3)(0.0f);

    /* f · Le · G / p, with the area-measure density written out. */
    float3 f = bsdf_eval(sp, ls.wi);
    return f * ls.Le * (cos_x * ls.cos_light / (ls.d2 * ls.pdf * ls.pmf));
}
