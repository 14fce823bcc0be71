float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream, uint* rays) {
    float big[4194304];
    big[*rays] = 1.0f;
    return (float3)(big[3]);
}
