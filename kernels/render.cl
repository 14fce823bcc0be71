/* Kernel entry points of the renderer. Global sizes are 1D; each entry checks its bound. */
#include "shared_types.h"
#include "camera.cl"
#include "estimators.cl"

/* One work-item per pixel sample of a batch. Work-item g renders sample
 * sample_begin + g % batch_samples (of spp in all) of pixel pixel_begin + g / batch_samples
 * < pixel_end (samples of a pixel adjacent) and writes samples[g] = (radiance, rays traced). */
kernel void render(global const Bvh4Node* nodes, global const TrianglePacket* packets,
                   global const TriangleInfo* triangle_info,
                   global const Material* materials, global const Light* lights,
                   global const float* light_cdf, global const AliasEntry* light_alias,
                   uint light_count, global const CameraGpu* camera, uint width, uint height,
                   uint seed, uint spp, float4 sky, float ao_distance, uint pixel_begin,
                   uint pixel_end, uint sample_begin, uint batch_samples,
                   global float4* samples) {
    size_t g = get_global_id(0);
    uint pixel = pixel_begin + (uint)(g / batch_samples);
    if (pixel >= pixel_end) return; /* the global size is rounded up to whole work-groups */

    SampleStream stream;
    stream.pixel = pixel;
    stream.sample = sample_begin + (uint)(g % batch_samples);
    stream.sample_count = spp;
    stream.seed = seed;

    SceneView scene;
    scene.nodes = nodes;
    scene.packets = packets;
    scene.triangle_info = triangle_info;
    scene.materials = materials;
    scene.lights.lights = lights;
    scene.lights.light_cdf = light_cdf;
    scene.lights.alias = light_alias;
    scene.lights.light_count = light_count;

    Environment env;
    env.sky = sky.xyz;
    env.ao_distance = ao_distance;

    float3 dir = camera_direction(camera, pixel % width, pixel / width,
                                  sample_2d(&stream, DIM_PIXEL_JITTER), width, height);
    Ray r = make_ray(camera->eye.xyz, dir);
    uint rays = 0u;
    float3 L = radiance(&scene, &r, &stream, &env, &rays);
    samples[g] = (float4)(L, (float)rays);
}

inline bool finite3(float3 v) {
    /* By the bits: isfinite may be folded away under -cl-fast-relaxed-math. */
    uint3 e = as_uint3(v) & 0x7f800000u;
    return all(e != (uint3)(0x7f800000u));
}

/* Sums each pixel's samples of a batch in chunks of MCRT_SAMPLES_PER_CHUNK consecutive samples,
 * in sample order. Work-item g handles chunk g % chunks of pixel g / chunks, chunks =
 * ceil(batch_samples / MCRT_SAMPLES_PER_CHUNK); writes sums[g] = (ΣR, ΣG, ΣB, non-finite count)
 * and sums_sq[g] = (ΣR², ΣG², ΣB², rays traced). Non-finite samples are counted and left out. */
kernel void reduce_chunks(global const float4* samples, uint batch_samples, uint pixel_count,
                          global float4* sums, global float4* sums_sq) {
    size_t g = get_global_id(0);
    uint chunks = (batch_samples + MCRT_SAMPLES_PER_CHUNK - 1u) / MCRT_SAMPLES_PER_CHUNK;
    uint pixel = (uint)(g / chunks);
    if (pixel >= pixel_count) return;
    uint begin = (uint)(g % chunks) * MCRT_SAMPLES_PER_CHUNK;
    uint end = min(begin + MCRT_SAMPLES_PER_CHUNK, batch_samples);
    float3 s = (float3)(0.0f), s2 = (float3)(0.0f);
    float bad = 0.0f, rays = 0.0f;
    for (uint k = begin; k < end; ++k) {
        float4 sample = samples[(size_t)pixel * batch_samples + k];
        float3 v = sample.xyz;
        rays += sample.w;
        if (finite3(v)) {
            s += v;
            s2 += v * v;
        } else {
            bad += 1.0f;
        }
    }
    sums[g] = (float4)(s, bad);
    sums_sq[g] = (float4)(s2, rays);
}

/* Writes the device's sizeof of each shared struct, to check them against the host's. */
kernel void shared_type_sizes(global uint* sizes) {
    if (get_global_id(0) != 0) return;
    sizes[0] = sizeof(BvhNode);
    sizes[1] = sizeof(Triangle);
    sizes[2] = sizeof(Material);
    sizes[3] = sizeof(Light);
    sizes[4] = sizeof(CameraGpu);
    sizes[5] = sizeof(AliasEntry);
    sizes[6] = sizeof(Bvh4Node);
    sizes[7] = sizeof(TrianglePacket);
    sizes[8] = sizeof(TriangleInfo);
}
