/* The tutorial's estimator (docs/ESTIMATORS.md): directions drawn from the surface's BSDF,
 * counting the emitters they hit: `--estimator bsdf` written with the public API (it renders its
 * image bit for bit, a test checks it). On Lambertian surfaces the density is cosθ/π, that of
 * `hemisphere-cosine`; on glTF's glossy materials it is the lobes' mixture (docs/ESTIMATORS.md).
 *
 *     mcrt render scenes/cornell/CornellBox-Original.gltf --out a.exr \
 *         --estimator-file examples/estimators/bsdf_directions.cl
 *
 * Estimate: f(wo, wi) · Le(hit, −wi) · cosθ / pdf_w(wi) (GI Compendium eq. 35), Le the sky
 * light's where wi leaves the scene under --sky. */

float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream,
                uint* rays) {
    BsdfSample bs = bsdf_sample(sp, sample_2d(stream, DIM_DIRECTION));
    if (!(bs.pdf_w > 0.0f) || bs.cos_theta <= 0.0f) return (float3)(0.0f);

    SurfacePoint seen;
    bool found = trace_bsdf_sample(scene, sp, &bs, rays, &seen);
    /* Through glass or off a mirror (a delta or transmitted sample, docs/ESTIMATORS.md) the path
     * counts what the direction finds; counted here too, it would count twice. */
    if (!bsdf_sample_is_direct(&bs)) return (float3)(0.0f);
    /* A direction that leaves the scene sees the sky light (black without --sky). */
    float3 Le = found ? emitted_radiance(&seen) : environment_radiance(scene, bs.wi);
    return bs.f * Le * (bs.cos_theta / bs.pdf_w);
}
