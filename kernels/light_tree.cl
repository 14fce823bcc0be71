/* Choosing a light by walking the light tree (host/render/light_tree.h) from the root: at each
 * inner node one child by the children's importance at the shading point, from one number
 * rescaled at every level (Conty Estevez & Kulla 2018; pbrt-v4's BVHLightSampler), and the pmf
 * of a given light by walking its stored path with the same arithmetic. */
#ifndef MCRT_LIGHT_TREE_CL
#define MCRT_LIGHT_TREE_CL

#include "discrete.cl"
#include "shared_types.h"

/* cos(max(0, θa − θb)) and sin(max(0, θa − θb)) from the sines and cosines of θa, θb ∈ [0, π]
 * (pbrt-v4's cosSubClamped / sinSubClamped). */
inline float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
    return cos_a > cos_b ? 1.0f : cos_a * cos_b + sin_a * sin_b;
}
inline float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
    return cos_a > cos_b ? 0.0f : sin_a * cos_b - cos_a * sin_b;
}

inline float safe_sqrt1m(float c) { return sqrt(max(0.0f, 1.0f - c * c)); }

/* Importance of a node at the shading point p with unit normal n (on the side the light must
 * reach): φ · cosθ'_light / d² · cosθ'_receiver, where the primes are the least angles that
 * the node's box and cone allow (Conty Estevez & Kulla 2018, eq. 3; pbrt-v4 LightBounds::
 * Importance). 0 when no light below can reach p's hemisphere. The receiver's bound is
 * one-sided because every BSDF here reflects only (a transmissive one would take |cos|). */
inline float light_node_importance(global const LightTreeNode* node, float3 p, float3 n) {
    float3 c = 0.5f * (node->lo.xyz + node->hi.xyz);
    float3 to_p = p - c;
    float d2 = dot(to_p, to_p);
    float r = node->radius, r2 = r * r; /* the box's bounding sphere */
    /* The distance is clamped to the bounding sphere's radius so that a point near or inside
     * the box does not get an unbounded importance. pbrt-v4 writes max(d², |diagonal|/2),
     * comparing a squared distance with a length (its scale-dependent slip); this compares
     * squares. */
    float d2_clamped = max(d2, r2);
    float inv_d = d2 > 0.0f ? 1.0f / sqrt(d2) : 0.0f;
    float3 wi = d2 > 0.0f ? to_p * inv_d : (float3)(0.0f, 0.0f, 1.0f); /* light → p */

    /* θ_w: between the cone's axis and the direction to p; either way for two-sided lights. */
    float cos_w = dot(node->axis.xyz, wi);
    if ((node->flags & LIGHT_NODE_TWO_SIDED) != 0u) cos_w = fabs(cos_w);
    float sin_w = safe_sqrt1m(cos_w);
    /* θ_b: half-angle of the bounding sphere seen from p; the whole sphere from inside it. */
    float sin_b = d2 > r2 ? min(r * inv_d, 1.0f) : 1.0f;
    float cos_b = d2 > r2 ? safe_sqrt1m(sin_b) : -1.0f;
    /* θ' = max(0, θ_w − θ_o − θ_b): the least angle between a normal and a direction to p. */
    float cos_o = node->hi.w, sin_o = node->sin_o;
    float cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    float sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    if (cos_p <= node->axis.w) return 0.0f;

    /* At the receiver: the least angle between n and a direction toward the box. */
    float cos_i = -dot(n, wi);
    float sin_i = safe_sqrt1m(cos_i);
    float cos_pi = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    if (cos_pi <= 0.0f) return 0.0f;
    return node->lo.w * cos_p / d2_clamped * cos_pi;
}

/* Probabilities of the first (*first) and second (*second) child, a and b, of an inner node at
 * (p, n): the one computation the sampler and the pmf share, so that both multiply the very
 * same floats. The children's bounds are tighter than the parent's, so both may have no
 * importance where the parent had some: they are then weighed by power alone (neither can
 * light p, so the choice only needs to be some choice), and the pmfs of all lights sum to 1
 * wherever the root has importance. False only for a non-finite importance. */
inline bool light_tree_split(global const LightTreeNode* a, global const LightTreeNode* b, float3 p,
                             float3 n, float* first, float* second) {
    float ia = light_node_importance(a, p, n), ib = light_node_importance(b, p, n);
    if (ia == 0.0f && ib == 0.0f) {
        ia = a->lo.w;
        ib = b->lo.w;
    }
    float sum = ia + ib;
    if (!(sum > 0.0f) || !isfinite(sum)) return false;
    *first = ia / sum;
    *second = ib / sum;
    return true;
}

/* Chooses a light at (p, n) from u on the 2^-24 grid refined by u_fine (discrete.cl). The
 * number (k + u_fine)·2^-24 is held as a 62-bit integer x in [0, range), range ≤ 2^62; each
 * level cuts the range at the first child's share t (the smaller share computed directly, so
 * that both keep their relative precision) and keeps the part x falls in, rescaled: the
 * stratification of u carries over as with CDF inversion, and x / range at the leaf is uniform for
 * the point on the light. pmf is the product of the children's probabilities: the chance of the
 * choice up to float rounding. pmf 0: no light can reach p (index is then meaningless). */
inline DiscreteSample sample_light_tree(global const LightTreeNode* nodes, float3 p, float3 n,
                                        float u, float u_fine) {
    DiscreteSample s;
    s.index = 0u;
    s.pmf = 0.0f;
    s.u_remap = 0.0f;
    global const LightTreeNode* node = nodes;
    /* No importance at the root: no light can reach p (or the tree is empty). */
    if (!(light_node_importance(node, p, n) > 0.0f)) return s;
    ulong x = ((ulong)unit_to_grid(u) << 38) + (ulong)(long)(u_fine * 0x1.0p38f);
    ulong range = 1ul << 62;
    float pmf = 1.0f;
    while ((node->flags & LIGHT_NODE_LEAF) == 0u) {
        global const LightTreeNode* a = nodes + node->child;
        float first, second;
        if (!light_tree_split(a, a + 1, p, n, &first, &second)) return s;
        /* Through signed 64-bit conversions (range ≤ 2^62): the hardware's, where unsigned
         * ones may be emulated. */
        float span = (float)(long)range;
        ulong t = first <= second ? (ulong)(long)(first * span)
                                  : range - min(range, (ulong)(long)(second * span));
        /* Each child with a share keeps at least one value of x. */
        if (first > 0.0f) t = max(t, 1ul);
        if (second > 0.0f) t = min(t, range - 1ul);
        uint which = x < t ? 0u : 1u;
        if (which == 0u) {
            range = t;
            pmf *= first;
        } else {
            x -= t;
            range -= t;
            pmf *= second;
        }
        node = a + which;
    }
    s.index = node->child;
    s.pmf = pmf;
    s.u_remap = min((float)(long)x / (float)(long)range, 0x1.fffffep-1f);
    return s;
}

/* Probability that sample_light_tree at (p, n) returns the light whose trail is `trail` and
 * path length depth_plus_one − 1 (LightTreePath): the same products along its path. */
inline float light_tree_pmf(global const LightTreeNode* nodes, uint trail, uint depth_plus_one,
                            float3 p, float3 n) {
    if (depth_plus_one == 0u) return 0.0f;
    global const LightTreeNode* node = nodes;
    if (!(light_node_importance(node, p, n) > 0.0f)) return 0.0f;
    float pmf = 1.0f;
    for (uint d = 0u; d + 1u < depth_plus_one; ++d) {
        global const LightTreeNode* a = nodes + node->child;
        float first, second;
        if (!light_tree_split(a, a + 1, p, n, &first, &second)) return 0.0f;
        uint which = (trail >> d) & 1u;
        pmf *= which == 0u ? first : second;
        node = a + which;
    }
    return pmf;
}

#endif
