/* BVH traversal over 4-wide nodes (Bvh4Node): closest hit for camera rays, any hit for shadow
 * rays. One slab test in float4 arithmetic covers a node's four children, one watertight test in
 * float4 arithmetic a leaf's packet of four triangles: PoCL runs each ray as scalar code, so SIMD
 * comes only from explicit vector types (docs/BENCHMARKS.md, "The traversal's steps, each
 * measured", has what each of these choices gained). */
#ifndef MCRT_BVH_TRAVERSE_CL
#define MCRT_BVH_TRAVERSE_CL

#include "intersect.cl"

#if defined(MCRT_TEXTURES)
#include "textures.cl"
/* What a ray query needs to test alpha at its candidate hits (MATERIAL_ALPHA_TESTED surfaces):
 * a masked or blended triangle is a hit only where alpha_keeps says so, in every query alike
 * (closest hit and any hit), so that a hole neither shades, nor shadows, nor emits. `key` is the
 * query's own (scene.cl, ray_alpha_test). */
typedef struct {
    TextureView textures;
    global const TriangleInfo* triangle_info;
    global const Material* materials;
    uint key;
} AlphaTest;

inline bool alpha_keeps_lane(const AlphaTest* at, uint lane, float b1, float b2) {
    TriangleInfo info = at->triangle_info[lane];
    if (!(at->materials[info.material].flags & MATERIAL_ALPHA_TESTED)) return true;
    return alpha_keeps(&at->textures, material_textures(&at->textures, info.material),
                       surface_uv(&at->textures, lane, b1, b2), at->key, lane);
}

/* The lanes of a packet's hits that alpha keeps; all of them for a query without a test. */
inline int4 alpha_kept_lanes(const AlphaTest* at, uint packet, int4 lanes, float4 b1, float4 b2) {
    if (!at || !any(lanes)) return lanes;
    uint base = MCRT_PACKET_WIDTH * packet;
    if (lanes.x && !alpha_keeps_lane(at, base, b1.x, b2.x)) lanes.x = 0;
    if (lanes.y && !alpha_keeps_lane(at, base + 1u, b1.y, b2.y)) lanes.y = 0;
    if (lanes.z && !alpha_keeps_lane(at, base + 2u, b1.z, b2.z)) lanes.z = 0;
    if (lanes.w && !alpha_keeps_lane(at, base + 3u, b1.w, b2.w)) lanes.w = 0;
    return lanes;
}
#else
/* Untextured builds test no alpha: every query passes a null AlphaTest. */
typedef struct {
    uint unused;
} AlphaTest;
#endif

/* A packet lane's triangle index without the MCRT_TRIANGLE_CULLED bit (shared_types.h), which
 * only single-sided builds set; the others mask nothing. */
#if defined(MCRT_SINGLE_SIDED)
#define PACKET_INDEX_MASK MCRT_TRIANGLE_INDEX_MASK
#else
#define PACKET_INDEX_MASK 0xffffffffu
#endif

/* A visited inner node pushes at most 3 of its children (the nearest is visited next), and the
 * stack holds entries of at most MCRT_BVH4_MAX_DEPTH (59) levels: 3 · 59 = 177 entries never
 * overflow. The any-hit traversal pushes up to 4 inner children and pops one at once, but only
 * at levels above the deepest, so its peak is lower. Pushes are still bounds-checked. */
#define BVH_STACK_SIZE (3 * MCRT_BVH4_MAX_DEPTH)

/* γ(3) = 3ε / (1 − 3ε), ε = 2^-24 (PBRT 3rd ed. 3.9.1). */
#define MCRT_GAMMA3 1.7881396e-7f

typedef struct {
    float t;
    float b1, b2;  /* barycentrics of p1, p2 */
    uint lane;     /* packet lane of the hit, 4 · packet + lane (TriangleInfo's index),
                      MCRT_NO_HIT on a miss */
} Hit;

/* The ray as the 4-wide slab test reads it: origin and inverse direction splatted, and per axis
 * the index of the node field holding the near plane (lo when the ray runs toward +, else hi;
 * the far plane is the other one, index ^ 1). */
typedef struct {
    float4 org_x, org_y, org_z;
    float4 inv_x, inv_y, inv_z;
    uint near_x, near_y, near_z;
} BoxRay;

inline BoxRay make_box_ray(const Ray* r) {
    BoxRay b;
    b.org_x = (float4)(r->org.x);
    b.org_y = (float4)(r->org.y);
    b.org_z = (float4)(r->org.z);
    b.inv_x = (float4)(r->inv_dir.x);
    b.inv_y = (float4)(r->inv_dir.y);
    b.inv_z = (float4)(r->inv_dir.z);
    b.near_x = r->inv_dir.x < 0.0f ? 1u : 0u;
    b.near_y = r->inv_dir.y < 0.0f ? 3u : 2u;
    b.near_z = r->inv_dir.z < 0.0f ? 5u : 4u;
    return b;
}

/* Entry distances of the ray into the four child boxes of a node, MAXFLOAT for a child it does
 * not enter before t_max. Near and far planes are chosen by the ray's signs, not by min/max of
 * the two: an inverted box (an empty slot) then has its near plane beyond its far one and is
 * always rejected, where min/max would read it as a huge box. */
inline float4 bvh4_entry(global const Bvh4Node* node, const BoxRay* b, float t_max) {
    global const float4* f = (global const float4*)node; /* lo_x, hi_x, lo_y, hi_y, lo_z, hi_z */
    float4 tn_x = (f[b->near_x] - b->org_x) * b->inv_x;
    float4 tf_x = (f[b->near_x ^ 1u] - b->org_x) * b->inv_x;
    float4 tn_y = (f[b->near_y] - b->org_y) * b->inv_y;
    float4 tf_y = (f[b->near_y ^ 1u] - b->org_y) * b->inv_y;
    float4 tn_z = (f[b->near_z] - b->org_z) * b->inv_z;
    float4 tf_z = (f[b->near_z ^ 1u] - b->org_z) * b->inv_z;
    /* min/max, not fmin/fmax: these add a NaN compare and a blend per lane on x86. */
    float4 t_enter = max(max(tn_x, tn_y), max(tn_z, (float4)(0.0f)));
    /* Conservative exit so rounding never culls a box the ray grazes (PBRT 3rd ed. 3.9.2). */
    float4 t_exit = min(min(tf_x, tf_y), tf_z) * (1.0f + 2.0f * MCRT_GAMMA3);
    t_exit = min(t_exit, (float4)(t_max));
    return select((float4)(MAXFLOAT), t_enter, t_enter <= t_exit);
}

/* The packet and lane mask of the triangle a ray leaves (a packet lane, 4 · packet + lane, or
 * MCRT_NO_HIT for none), which the traversal never reports: a flat triangle cannot be hit
 * again by a ray leaving it, so skipping it is exact. */
typedef struct {
    uint packet;
    int4 lanes;
} SkipLane;

inline SkipLane make_skip_lane(uint lane) {
    SkipLane s;
    s.packet = lane == MCRT_NO_HIT ? MCRT_NO_HIT : lane / MCRT_PACKET_WIDTH;
    s.lanes = (int4)(0, 1, 2, 3) == (int4)((int)(lane % MCRT_PACKET_WIDTH));
    return s;
}

inline int4 skipped_lanes(const SkipLane* s, uint packet) {
    return packet == s->packet ? s->lanes : (int4)(0);
}

/* Closest hit with t in (t_min, t_max), never on the triangle at packet lane `skip`
 * (MCRT_NO_HIT: none), nor where `alpha` cuts a surface (textured builds; null: no test). Children are visited nearest first; the others wait on the
 * stack with their entry distances and are skipped once a nearer hit is found. An empty scene's
 * root has only empty slots, so no ray enters it. */
inline __attribute__((always_inline)) Hit bvh_closest_hit_beyond(
    global const Bvh4Node* nodes, global const TrianglePacket* packets, const Ray* r, float t_min,
    float t_max, uint skip, const AlphaTest* alpha) {
    Hit hit;
    hit.t = t_max;
    hit.b1 = hit.b2 = 0.0f;
    hit.lane = MCRT_NO_HIT;
    uint hit_index = UINT_MAX; /* the winner's triangle index */
    /* How far a box may begin and still hold a triangle at the held hit's t: t_max until a hit
     * is held, then beyond the hit's t by the hit's rounding bound δt (intersect.cl) and the box
     * test's (1 + 2γ3). A hit on a shared vertex or edge lies on its leaf boxes' faces, whose
     * entry may round past the hit's t: without the margin, which of the tied triangles wins
     * would depend on which box the tree culls. A tie with a triangle whose own δt is far larger
     * than the winner's could still be culled. */
    float reach = t_max;

    BoxRay b = make_box_ray(r);
    PacketRay q = make_packet_ray(r);
    SkipLane s = make_skip_lane(skip);
    /* One spare entry at the end takes the writes of children that are not pushed. */
    uint stack_ref[BVH_STACK_SIZE + 1], stack_count[BVH_STACK_SIZE + 1];
    float stack_t[BVH_STACK_SIZE + 1];
    int sp = 0;
    /* The current child: a Bvh4Node index when count is 0, else a leaf's first packet. */
    uint ref = 0u, count = 0u;
    for (;;) {
        if (count == 0u) {
            global const Bvh4Node* node = nodes + ref;
            float4 t4 = bvh4_entry(node, &b, reach);
            int4 entered = t4 != (float4)(MAXFLOAT);
            if (any(entered)) {
                /* Children are visited nearest first, a later slot first among equals. A child's
                 * visit rank is the number of entered children before it in that order, found
                 * by compares against the rotated distances (a sorting network without
                 * branches or private arrays: the insertion sort it replaces mispredicted on
                 * every node, docs/BENCHMARKS.md, "Kernel changes measured"). Non-entered children are at
                 * MAXFLOAT, after every entered one. */
                float4 r1 = t4.yzwx, r2 = t4.zwxy, r3 = t4.wxyz;
                int4 before1 = (r1 < t4) | ((r1 == t4) & (int4)(-1, -1, -1, 0));
                int4 before2 = (r2 < t4) | ((r2 == t4) & (int4)(-1, -1, 0, 0));
                int4 before3 = (r3 < t4) | ((r3 == t4) & (int4)(-1, 0, 0, 0));
                int4 rank = -(before1 + before2 + before3);
                int n = -(entered.x + entered.y + entered.z + entered.w);
                /* Rank 0 is visited next; rank k > 0 goes to stack entry sp + n - 1 - k, so
                 * that the stack pops ranks 1, 2, ... in turn. Children that are not pushed
                 * (not entered, rank 0, or beyond a full stack) write the spare entry. */
                int4 pos = (int4)(sp + n - 1) - rank;
                pos = select((int4)(BVH_STACK_SIZE), pos,
                             entered & (rank > 0) & (pos < (int4)(BVH_STACK_SIZE)));
                uint4 child = vload4(0, node->child), cnt = vload4(0, node->count);
                stack_ref[pos.x] = child.x, stack_count[pos.x] = cnt.x, stack_t[pos.x] = t4.x;
                stack_ref[pos.y] = child.y, stack_count[pos.y] = cnt.y, stack_t[pos.y] = t4.y;
                stack_ref[pos.z] = child.z, stack_count[pos.z] = cnt.z, stack_t[pos.z] = t4.z;
                stack_ref[pos.w] = child.w, stack_count[pos.w] = cnt.w, stack_t[pos.w] = t4.w;
                sp = min(sp + n - 1, BVH_STACK_SIZE);
                int4 first = entered & (rank == 0);
                ref = first.x ? child.x : first.y ? child.y : first.z ? child.z : child.w;
                count = first.x ? cnt.x : first.y ? cnt.y : first.z ? cnt.z : cnt.w;
                continue;
            }
        } else {
            /* A leaf's packets, four triangles per test. The winner is the smallest t, and among
             * equal t the smallest triangle index, so the hit does not depend on the tree's layout
             * or the order it is walked in. Once a hit is held, lanes at exactly its t are tested
             * too (the bound is the next float above it), since one may hold a smaller index. */
            global const TrianglePacket* pk = packets + ref;
            float t_bound = hit.lane == MCRT_NO_HIT ? hit.t : nextafter(hit.t, MAXFLOAT);
            for (uint k = 0; k < count; k += MCRT_PACKET_WIDTH, ++pk) {
                float4 t4 = (float4)(0.0f), b1 = (float4)(0.0f), b2 = (float4)(0.0f);
                float4 dt4 = (float4)(0.0f);
                uint packet = ref + k / MCRT_PACKET_WIDTH;
                int4 lanes = intersect_packet(&q, pk, t_min, t_bound, skipped_lanes(&s, packet),
                                              false, &t4, &b1, &b2, &dt4);
#if defined(MCRT_TEXTURES)
                lanes = alpha_kept_lanes(alpha, packet, lanes, b1, b2);
#endif
                /* The nearest hit lane, the smallest triangle index among equals, by compares
                 * instead of a loop over private arrays; taken by selects, not a branch on
                 * whether any lane hit (which mispredicted). */
                float4 tm = select((float4)(MAXFLOAT), t4, lanes);
                float2 m2 = min(tm.xy, tm.zw);
                float m = min(m2.x, m2.y);
                int i = tm.x == m ? 0 : tm.y == m ? 1 : tm.z == m ? 2 : 3;
                int4 at_m = lanes & (tm == (float4)(m));
                uint mi = pk->index[i] & PACKET_INDEX_MASK;
                /* Ties (two lanes at m, or m at the held t) are rare: a branch that is almost
                 * never taken, rather than the index compares on every packet. */
                if (-(at_m.x + at_m.y + at_m.z + at_m.w) > 1) {
                    uint4 idx = select((uint4)(UINT_MAX),
                                       vload4(0, pk->index) & (uint4)(PACKET_INDEX_MASK),
                                       as_uint4(at_m));
                    uint2 i2 = min(idx.xy, idx.zw);
                    mi = min(i2.x, i2.y);
                    i = idx.x == mi ? 0 : idx.y == mi ? 1 : idx.z == mi ? 2 : 3;
                }
                bool nearer = m < hit.t || (m == hit.t && any(lanes) && mi < hit_index);
                float hb1 = i == 0 ? b1.x : i == 1 ? b1.y : i == 2 ? b1.z : b1.w;
                float hb2 = i == 0 ? b2.x : i == 1 ? b2.y : i == 2 ? b2.z : b2.w;
                uint lane = MCRT_PACKET_WIDTH * packet + (uint)i;
                hit.t = nearer ? m : hit.t;
                hit.b1 = nearer ? hb1 : hit.b1;
                hit.b2 = nearer ? hb2 : hit.b2;
                hit.lane = nearer ? lane : hit.lane;
                hit_index = nearer ? mi : hit_index;
                t_bound = nextafter(hit.t, MAXFLOAT);
                float hdt = i == 0 ? dt4.x : i == 1 ? dt4.y : i == 2 ? dt4.z : dt4.w;
                reach = nearer ? min(t_max, (m + hdt) * (1.0f + 2.0f * MCRT_GAMMA3)) : reach;
            }
        }
        /* Pop, skipping children entered beyond the reach of the closest hit found since they
         * were pushed; a child entered at the hit's t, or within rounding of it, is visited, as
         * it may hold a smaller index there. */
        for (;;) {
            if (sp == 0) return hit;
            --sp;
            if (stack_t[sp] <= reach) break;
        }
        ref = stack_ref[sp];
        count = stack_count[sp];
    }
}

/* Closest hit with t in (0, t_max), never on the triangle at packet lane `skip`; for a ray that
 * leaves a surface (skip is its triangle, not MCRT_NO_HIT) also beyond δt, the hit's own
 * rounding bound (intersect.cl). Only the winner's δt is computed: a winner within it (a
 * coplanar neighbour of the surface the ray leaves, hit at t ≈ 0 by rounding) is passed over by
 * traversing again beyond its δt. A camera ray starts on no surface and needs no bound (what it
 * would cost: docs/BENCHMARKS.md, "Rays leaving surfaces"). */
inline Hit bvh_closest_hit(global const Bvh4Node* nodes, global const TrianglePacket* packets,
                           const Ray* r, float t_max, uint skip, const AlphaTest* alpha) {
    float t_min = 0.0f;
    for (;;) {
        Hit hit = bvh_closest_hit_beyond(nodes, packets, r, t_min, t_max, skip, alpha);
        if (hit.lane == MCRT_NO_HIT || skip == MCRT_NO_HIT) return hit;
        PacketRay q = make_packet_ray(r);
        float bound = lane_t_rounding_bound(&q, packets + hit.lane / MCRT_PACKET_WIDTH,
                                            hit.lane % MCRT_PACKET_WIDTH);
        if (hit.t > bound) return hit;
        t_min = bound; /* strictly larger each time: the loop ends */
    }
}

/* True if anything but the triangle at packet lane `skip` (MCRT_NO_HIT: none) blocks the ray
 * in (δt, t_max − δt), each hit's δt its own rounding bound (intersect.cl): a hit that rounding
 * may have put at either end of the segment does not block it. Leaves are tested as soon as their box is
 * entered (any hit ends the search); inner children go on the stack. Slots are taken from the
 * last to the first, so that slot 0 (the binary tree's leftmost child) is popped first: on the
 * bench's shadow rays this visited 6.7 nodes per ray in Sponza against 9.7 in slot order and 9.0
 * nearest first, but 8.3 against 5.5 in the modern hall (docs/BENCHMARKS.md, "Ray traversal"). No order
 * wins everywhere; this one gave the best worst-case ratio to Embree over the bench scenes. */
inline bool bvh_any_hit(global const Bvh4Node* nodes, global const TrianglePacket* packets,
                        const Ray* r, float t_max, uint skip, const AlphaTest* alpha) {
    BoxRay b = make_box_ray(r);
    PacketRay q = make_packet_ray(r);
    SkipLane sk = make_skip_lane(skip);
    uint stack[BVH_STACK_SIZE];
    int sp = 0;
    uint ref = 0u;
    for (;;) {
        global const Bvh4Node* node = nodes + ref;
        float4 t4 = bvh4_entry(node, &b, t_max);
        float t_in[4] = {t4.x, t4.y, t4.z, t4.w};
        for (int s = 3; s >= 0; --s) {
            if (t_in[s] == MAXFLOAT) continue;
            uint child = node->child[s], count = node->count[s];
            if (count == 0u) {
                if (sp < BVH_STACK_SIZE) stack[sp++] = child;
                continue;
            }
            global const TrianglePacket* pk = packets + child;
            for (uint k = 0; k < count; k += MCRT_PACKET_WIDTH, ++pk) {
                float4 t4, b1, b2, dt4;
                int4 skipped = skipped_lanes(&sk, child + k / MCRT_PACKET_WIDTH);
                int4 lanes =
                    intersect_packet(&q, pk, 0.0f, t_max, skipped, true, &t4, &b1, &b2, &dt4);
#if defined(MCRT_TEXTURES)
                lanes = alpha_kept_lanes(alpha, child + k / MCRT_PACKET_WIDTH, lanes, b1, b2);
#endif
                if (any(lanes)) return true;
            }
        }
        if (sp == 0) return false;
        ref = stack[--sp];
    }
}

#endif
