/* BVH traversal: closest hit for camera rays, any hit for shadow rays. */
#ifndef MCRT_BVH_TRAVERSE_CL
#define MCRT_BVH_TRAVERSE_CL

#include "intersect.cl"

/* Matches kMaxBvhDepth on the host: the builder never makes a deeper tree. */
#define BVH_STACK_SIZE 64

#define NO_HIT 0xffffffffu

/* γ(3) = 3ε / (1 − 3ε), ε = 2^-24 (PBRT 3rd ed. 3.9.1). */
#define MCRT_GAMMA3 1.7881396e-7f

typedef struct {
    float t;
    float b1, b2;  /* barycentrics of p1, p2 */
    uint triangle; /* index in the leaf-ordered triangle array, NO_HIT on a miss */
} Hit;

/* Entry distance of the ray into the box if it enters before t_max, else +huge. Slab test with
 * min/max: fmin/fmax keep NaN semantics on PoCL and cost four times as much. */
inline float box_entry(float4 lo, float4 hi, const Ray* r, float t_max) {
    float3 t0 = (lo.xyz - r->org) * r->inv_dir;
    float3 t1 = (hi.xyz - r->org) * r->inv_dir;
    float3 tn = min(t0, t1), tf = max(t0, t1);
    float t_enter = max(max(tn.x, tn.y), max(tn.z, 0.0f));
    /* Conservative exit so rounding never culls a box the ray grazes (PBRT 3rd ed. 3.9.2). */
    float t_exit = min(min(tf.x, tf.y), tf.z) * (1.0f + 2.0f * MCRT_GAMMA3);
    t_exit = min(t_exit, t_max);
    return t_enter <= t_exit ? t_enter : MAXFLOAT;
}

/* An empty scene's root is a leaf without triangles whose box is inverted (lo > hi); the slab
 * test would read an inverted box as a huge one, and count 0 would read as an inner node. */
inline bool root_is_empty(const BvhNode* root) { return root->lo.x > root->hi.x; }

/* Closest hit with t in (0, t_max). */
inline Hit bvh_closest_hit(global const BvhNode* nodes, global const Triangle* triangles,
                           const Ray* r, float t_max) {
    Hit hit;
    hit.t = t_max;
    hit.b1 = hit.b2 = 0.0f;
    hit.triangle = NO_HIT;

    uint stack[BVH_STACK_SIZE];
    float stack_t[BVH_STACK_SIZE];
    int sp = 0;
    BvhNode node = nodes[0];
    if (root_is_empty(&node) || box_entry(node.lo, node.hi, r, t_max) == MAXFLOAT) return hit;
    for (;;) {
        uint first = as_uint(node.lo.w);
        uint count = as_uint(node.hi.w);
        bool descend = false;
        if (count == 0u) {
            /* Inner node: visit the nearer child first, push the farther one. */
            BvhNode left = nodes[first], right = nodes[first + 1u];
            float tl = box_entry(left.lo, left.hi, r, hit.t);
            float tr = box_entry(right.lo, right.hi, r, hit.t);
            if (tl != MAXFLOAT && tr != MAXFLOAT) {
                bool left_first = tl <= tr;
                stack[sp] = left_first ? first + 1u : first;
                stack_t[sp] = left_first ? tr : tl;
                ++sp;
                node = left_first ? left : right;
                descend = true;
            } else if (tl != MAXFLOAT) {
                node = left;
                descend = true;
            } else if (tr != MAXFLOAT) {
                node = right;
                descend = true;
            }
        } else {
            for (uint i = first; i < first + count; ++i) {
                float t, b1, b2;
                if (intersect_triangle(r, triangles[i].p0, triangles[i].p1, triangles[i].p2,
                                       hit.t, &t, &b1, &b2)) {
                    hit.t = t;
                    hit.b1 = b1;
                    hit.b2 = b2;
                    hit.triangle = i;
                }
            }
        }
        if (descend) continue;
        /* Pop, skipping nodes entered beyond the closest hit found since they were pushed. */
        for (;;) {
            if (sp == 0) return hit;
            --sp;
            if (stack_t[sp] < hit.t) break;
        }
        node = nodes[stack[sp]];
    }
}

/* True if anything blocks the ray in (0, t_max). */
inline bool bvh_any_hit(global const BvhNode* nodes, global const Triangle* triangles, const Ray* r,
                        float t_max) {
    uint stack[BVH_STACK_SIZE];
    int sp = 0;
    BvhNode node = nodes[0];
    if (root_is_empty(&node) || box_entry(node.lo, node.hi, r, t_max) == MAXFLOAT) return false;
    for (;;) {
        uint first = as_uint(node.lo.w);
        uint count = as_uint(node.hi.w);
        if (count == 0u) {
            BvhNode left = nodes[first], right = nodes[first + 1u];
            bool hl = box_entry(left.lo, left.hi, r, t_max) != MAXFLOAT;
            bool hr = box_entry(right.lo, right.hi, r, t_max) != MAXFLOAT;
            if (hl && hr) {
                stack[sp++] = first + 1u;
                node = left;
                continue;
            }
            if (hl || hr) {
                node = hl ? left : right;
                continue;
            }
        } else {
            for (uint i = first; i < first + count; ++i) {
                float t, b1, b2;
                if (intersect_triangle(r, triangles[i].p0, triangles[i].p1, triangles[i].p2, t_max,
                                       &t, &b1, &b2))
                    return true;
            }
        }
        if (sp == 0) return false;
        node = nodes[stack[--sp]];
    }
}

#endif
