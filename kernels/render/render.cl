/* Kernel entry points of the renderer. Global sizes are 1D; each entry checks its bound. */
#include "shared_types.h"
#include "camera.cl"
#include "estimators.cl"
#include "user_estimator.cl"
#include "path.cl"

/* One work-item per pixel sample of a batch. Work-item g renders sample
 * p.sample_begin + g % p.batch_samples (of p.spp in all) of pixel
 * p.pixel_begin + g / p.batch_samples < p.pixel_end (samples of a pixel adjacent) along a path
 * of at most p.max_depth reflections (path.cl) and writes samples[g] = (the radiance's bits, the
 * packed PathRecord). Arguments in the order of RenderArgument. */
kernel void render(global const Bvh4Node* nodes, global const TrianglePacket* packets,
                   global const TriangleInfo* triangle_info, global const Material* materials,
                   global const Light* lights, global const uint* light_selection,
                   global const TriangleSurface* surfaces, global const uint* textures,
                   global const float* environment, global const PunctualGpu* punctual,
                   global const CameraGpu* camera,
                   global uint4* samples, RenderParams p) {
    size_t g = get_global_id(0);
    uint pixel = p.pixel_begin + (uint)(g / p.batch_samples);
    if (pixel >= p.pixel_end) return; /* the global size is rounded up to whole work-groups */

    SampleStream stream;
    stream.pixel = pixel;
    stream.index = p.sample_begin + (uint)(g % p.batch_samples);
    stream.replicate = stream.index % p.replicates;
    stream.sample = stream.index / p.replicates;
    stream.sample_count = p.spp / p.replicates;
    stream.seed = p.seed;
    stream.vertex = 0u;

    SceneView scene;
    scene.nodes = nodes;
    scene.packets = packets;
    scene.triangle_info = triangle_info;
    scene.materials = materials;
    scene.lights = light_set(lights, p.light_count, light_selection, p.light_tree_nodes);
#if defined(MCRT_PUNCTUAL)
    scene.lights.punctual = punctual;
    scene.lights.punctual_count = p.punctual_count;
#endif
    scene.env.sky = p.sky.xyz;
    scene.env.ao_distance = p.ao_distance;
    scene.env.sky_pmf = p.sky.w;
#if defined(MCRT_ENVIRONMENT_MAP)
    scene.env.map.rgb = environment;
    scene.env.map.cdf = environment + 3u * p.env_width * p.env_height;
    scene.env.map.width = p.env_width;
    scene.env.map.height = p.env_height;
    scene.env.map.cos_rot = p.env_cos_rot;
    scene.env.map.sin_rot = p.env_sin_rot;
#endif
    PathContinuation continuation;
    continuation.given = false;
    scene.continuation = p.max_depth > 1u ? &continuation : 0; /* direct lighting goes no further */
#if defined(MCRT_TEXTURES)
    uint alpha_key = 0u;
    scene.textures.data = textures;
    scene.textures.surfaces = surfaces;
    scene.alpha_key = &alpha_key;
#endif

    float3 dir = camera_direction(camera, pixel % p.width, pixel / p.width,
                                  sample_2d(&stream, DIM_PIXEL_JITTER), p.width, p.height);
    Ray r = make_ray(camera->eye.xyz, dir);
    PathRecord record = {0u, 0u, false};
    float3 L = path_radiance(&scene, &r, &stream, p.max_depth, p.rr_depth, &record);
#if defined(MCRT_TEST_WRONG_VALUES) /* a device that computes wrong values (test_hooks.h) */
    L *= 1.0f + 0x1.0p-20f;
#endif
    samples[g] = (uint4)(as_uint3(L), pack_path_record(&record));
}

inline bool finite3(float3 v) {
    /* By the bits: isfinite may be folded away under -cl-fast-relaxed-math. */
    uint3 e = as_uint3(v) & 0x7f800000u;
    return all(e != (uint3)(0x7f800000u));
}

/* Sums each pixel's samples of a batch in chunks of MCRT_SAMPLES_PER_CHUNK consecutive samples,
 * in sample order, one run per replicate within each chunk (the chunk starts on a multiple of
 * 16, which `replicates` divides: local sample k belongs to replicate k % replicates).
 * Work-item g handles chunk g % chunks of pixel g / chunks, chunks =
 * ceil(batch_samples / MCRT_SAMPLES_PER_CHUNK), and writes sums[g · replicates + r] for each
 * replicate r (ChunkSums: shifted and scaled, so that nothing cancels or overflows; with the
 * rays, path vertices and roulette ends of the packed PathRecords). Non-finite samples are
 * counted and read as 0. */
kernel void reduce_chunks(global const uint4* samples, uint batch_samples, uint pixel_count,
                          uint replicates, global ChunkSums* sums) {
    size_t g = get_global_id(0);
    uint chunks = (batch_samples + MCRT_SAMPLES_PER_CHUNK - 1u) / MCRT_SAMPLES_PER_CHUNK;
    uint pixel = (uint)(g / chunks);
    if (pixel >= pixel_count) return;
    uint begin = (uint)(g % chunks) * MCRT_SAMPLES_PER_CHUNK;
    uint end = min(begin + MCRT_SAMPLES_PER_CHUNK, batch_samples);
    global const uint4* x = samples + (size_t)pixel * batch_samples;
    for (uint r = 0u; r < replicates; ++r) {
        /* The shift (first value) and the largest magnitude, per channel. */
        float3 shift = (float3)(0.0f), largest = (float3)(0.0f);
        float bad = 0.0f, rays = 0.0f, n = 0.0f;
        uint vertices = 0u, roulette = 0u;
        for (uint k = begin + r; k < end; k += replicates) {
            uint4 sample = x[k];
            float3 L = as_float3(sample.xyz);
            bool ok = finite3(L);
            float3 v = ok ? L : (float3)(0.0f);
            if (n == 0.0f) shift = v;
            largest = fmax(largest, fabs(v));
            bad += ok ? 0.0f : 1.0f;
            rays += (float)path_record_rays(sample.w);
            vertices += path_record_vertices(sample.w);
            roulette += path_record_roulette(sample.w);
            n += 1.0f;
        }
        /* 2^e at most the largest magnitude: scaled values are below 2 in magnitude. */
        int3 e = select((int3)(0), ilogb(largest), largest > (float3)(0.0f));
        float3 s = (float3)(0.0f), s2 = (float3)(0.0f);
        float3 shift_scaled = ldexp(shift, -e);
        for (uint k = begin + r; k < end; k += replicates) {
            float3 v = as_float3(x[k].xyz);
            v = finite3(v) ? v : (float3)(0.0f);
            float3 d = ldexp(v, -e) - shift_scaled;
            s += d;
            s2 += d * d;
        }
        ChunkSums out;
        out.shift = (float4)(shift, bad);
        out.sum = (float4)(s, rays);
        out.sum_sq = (float4)(s2, n);
        out.exponent = (float4)(convert_float3(e), (float)(vertices + (roulette << 15)));
        sums[g * replicates + r] = out;
    }
}

/* The device's view of every shared struct, in the order of MCRT_SHARED_LAYOUT: for each struct
 * its size and alignment, then each listed member's offset. */
#define MCRT_PROBE_TYPE(T, size, align) \
    layout[k++] = (uint)sizeof(T);      \
    layout[k++] = (uint)__alignof__(T);
#define MCRT_PROBE_FIELD(T, member, offset) layout[k++] = (uint)__builtin_offsetof(T, member);
kernel void shared_type_layout(global uint* layout) {
    if (get_global_id(0) != 0) return;
    uint k = 0u;
    MCRT_SHARED_LAYOUT(MCRT_PROBE_TYPE, MCRT_PROBE_FIELD)
}
