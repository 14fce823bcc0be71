/* Probe for docs/BENCHMARKS.md ("Where a sample's time goes", its work-group bullet): does PoCL's work-item
 * loop vectoriser make a slab test cheaper when a work-group tests one node for all its rays?
 * Both kernels test every ray against the same NODES 4-wide nodes (random boxes), with the
 * arithmetic of bvh4_entry (kernels/traversal/bvh_traverse.cl).
 *   slab_group:  scalar code per child, one node per barrier-separated region, and a vote in
 *                local memory (work-item 0 ORs the masks), as a group traversal would need:
 *                the regions between barriers are loop-free, so PoCL vectorises them across
 *                work-items (POCL_VECTORIZER_REMARKS=1 shows "vectorized loop").
 *   slab_barrier: the same regions with one barrier per node and no vote (each work-item reads
 *                a neighbour's mask): what the barrier alone costs.
 *   slab_float4: one work-item per ray with float4 arithmetic over the four children, as
 *                mcrt traverses today. */

/* The entered children of one node (bit c for child c), scalar code as a work-item loop
 * vectorises it: the arithmetic of bvh4_entry, one child at a time. */
inline uint slab_mask(global const float* f, float4 o, float4 iv) {
    float ox = o.x, oy = o.y, oz = o.z, ix = iv.x, iy = iv.y, iz = iv.z, t_max = o.w;
    bool nx = ix < 0.0f, ny = iy < 0.0f, nz = iz < 0.0f;
    uint m = 0u;
    for (int c = 0; c < 4; ++c) {
        float lx = f[c], hx = f[4 + c], ly = f[8 + c], hy = f[12 + c], lz = f[16 + c],
              hz = f[20 + c];
        float tnx = ((nx ? hx : lx) - ox) * ix, tfx = ((nx ? lx : hx) - ox) * ix;
        float tny = ((ny ? hy : ly) - oy) * iy, tfy = ((ny ? ly : hy) - oy) * iy;
        float tnz = ((nz ? hz : lz) - oz) * iz, tfz = ((nz ? lz : hz) - oz) * iz;
        float t_enter = max(max(tnx, tny), max(tnz, 0.0f));
        float t_exit = min(min(min(tfx, tfy), tfz) * 1.0000004f, t_max);
        m |= (t_enter <= t_exit ? 1u : 0u) << c;
    }
    return m;
}

__attribute__((reqd_work_group_size(64, 1, 1)))
kernel void slab_group(global const float* nodes, global const float4* org,
                       global const float4* inv, global uint* out, uint node_count) {
    uint lid = get_local_id(0), g = get_global_id(0);
    local uint masks[64];
    local uint vote;
    float4 o = org[g], iv = inv[g]; /* t_max in o.w */
    uint acc = 0u;
    for (uint k = 0; k < node_count; ++k) {
        /* lo_x[4], hi_x[4], lo_y, hi_y, lo_z, hi_z */
        uint m = slab_mask(nodes + 24 * k, o, iv);
        masks[lid] = m;
        barrier(CLK_LOCAL_MEM_FENCE);
        if (lid == 0u) {
            uint v = 0u;
            for (int i = 0; i < 64; ++i) v |= masks[i];
            vote = v;
        }
        barrier(CLK_LOCAL_MEM_FENCE);
        acc += vote + m;
    }
    out[g] = acc;
}

__attribute__((reqd_work_group_size(64, 1, 1)))
kernel void slab_barrier(global const float* nodes, global const float4* org,
                       global const float4* inv, global uint* out, uint node_count) {
    uint lid = get_local_id(0), g = get_global_id(0);
    local uint masks[64];
    float4 o = org[g], iv = inv[g]; /* t_max in o.w */
    uint acc = 0u;
    for (uint k = 0; k < node_count; ++k) {
        /* lo_x[4], hi_x[4], lo_y, hi_y, lo_z, hi_z */
        uint m = slab_mask(nodes + 24 * k, o, iv);
        masks[lid] = m;
        barrier(CLK_LOCAL_MEM_FENCE);
        acc += masks[(lid + 1u) & 63u] + m;
    }
    out[g] = acc;
}

kernel void slab_float4(global const float* nodes, global const float4* org,
                        global const float4* inv, global uint* out, uint node_count) {
    uint g = get_global_id(0);
    float4 o = org[g], iv = inv[g];
    float4 ox = (float4)(o.x), oy = (float4)(o.y), oz = (float4)(o.z);
    float4 ix = (float4)(iv.x), iy = (float4)(iv.y), iz = (float4)(iv.z);
    uint nx = iv.x < 0.0f ? 1u : 0u, ny = iv.y < 0.0f ? 3u : 2u, nz = iv.z < 0.0f ? 5u : 4u;
    float t_max = o.w;
    uint acc = 0u;
    for (uint k = 0; k < node_count; ++k) {
        global const float4* f = (global const float4*)(nodes + 24 * k);
        float4 tnx = (f[nx] - ox) * ix, tfx = (f[nx ^ 1u] - ox) * ix;
        float4 tny = (f[ny] - oy) * iy, tfy = (f[ny ^ 1u] - oy) * iy;
        float4 tnz = (f[nz] - oz) * iz, tfz = (f[nz ^ 1u] - oz) * iz;
        float4 t_enter = max(max(tnx, tny), max(tnz, (float4)(0.0f)));
        float4 t_exit = min(min(min(tfx, tfy), tfz) * 1.0000004f, (float4)(t_max));
        int4 e = t_enter <= t_exit;
        acc += (uint)((e.x & 1) | (e.y & 2) | (e.z & 4) | (e.w & 8));
    }
    out[g] = acc;
}
