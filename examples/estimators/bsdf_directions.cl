/* The tutorial's estimator (docs/ESTIMATORS.md): directions drawn from the surface's BSDF,
 * counting the emitters they hit: `--estimator bsdf` written with the public API (it renders its
 * image bit for bit, a test checks it). On Lambertian surfaces the density is cosθ/π, that of
 * `hemisphere-cosine`; on glTF's glossy materials it is the lobes' mixture (docs/ESTIMATORS.md).
 *
 *     mcrt render scenes/cornell/CornellBox-Original.gltf --out a.exr \
 *         --estimator-file examples/estimators/bsdf_directions.cl
 *
 * Estimate: f(wo, wi) · Le(hit, −wi) · cosθ / pdf_w(wi) (GI Compendium eq. 35). */

float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream,
                uint* rays) {
    BsdfSample bs = bsdf_sample(sp, sample_2d(stream, DIM_DIRECTION));
    if (!(bs.pdf_w > 0.0f) || bs.cos_theta <= 0.0f) return (float3)(0.0f);

    SurfacePoint seen;
    if (!trace_from(scene, sp, bs.wi, rays, &seen)) return (float3)(0.0f); /* left the scene */
    return bs.f * emitted_radiance(&seen) * (bs.cos_theta / bs.pdf_w);
}
