/* Ray-query entry points on rays given in buffers: for tests against a reference tracer and
 * for `mcrt bench`. */
#include "shared_types.h"
#include "bvh_traverse.cl"

/* Closest hit of ray g: origins[g].xyz, directions[g].xyz, t_max in origins[g].w. Writes
 * hits[g] = (t, b1, b2, the scene's triangle index as uint bits; MCRT_NO_HIT on a miss). */
kernel void trace_closest(global const Bvh4Node* nodes, global const TrianglePacket* packets,
                          global const float4* origins, global const float4* directions,
                          uint ray_count, global float4* hits) {
    size_t g = get_global_id(0);
    if (g >= ray_count) return;
    Ray r = make_ray(origins[g].xyz, directions[g].xyz);
    Hit h = bvh_closest_hit(nodes, packets, &r, origins[g].w, MCRT_NO_HIT, 0);
    uint triangle = h.lane == MCRT_NO_HIT
                        ? MCRT_NO_HIT
                        : packets[h.lane / MCRT_PACKET_WIDTH].index[h.lane % MCRT_PACKET_WIDTH] &
                              PACKET_INDEX_MASK;
    hits[g] = (float4)(h.t, h.b1, h.b2, as_float(triangle));
}

/* Occlusion of ray g in (0, t_max): occluded[g] = 1 if anything blocks it, else 0. */
kernel void trace_any(global const Bvh4Node* nodes, global const TrianglePacket* packets,
                      global const float4* origins, global const float4* directions,
                      uint ray_count, global uint* occluded) {
    size_t g = get_global_id(0);
    if (g >= ray_count) return;
    Ray r = make_ray(origins[g].xyz, directions[g].xyz);
    occluded[g] = bvh_any_hit(nodes, packets, &r, origins[g].w, MCRT_NO_HIT, 0) ? 1u : 0u;
}
