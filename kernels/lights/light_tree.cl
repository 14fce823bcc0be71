/* Choosing a light by walking the light tree (host/render/light_tree.h) from the root: at each
 * node one of its four slots by the slots' importance at the shading point, from one number
 * rescaled at every level (Conty Estevez & Kulla 2018; pbrt-v4's BVHLightSampler, four wide),
 * and the pmf of a given light by walking its stored path with the same arithmetic. */
#ifndef MCRT_LIGHT_TREE_CL
#define MCRT_LIGHT_TREE_CL

#include "discrete.cl"
#include "shared_types.h"

/* Importance of a node's four slots at the shading point p with unit normal n (on the side the
 * light must reach), one vector component each: φ · cosθ'_light · cosθ'_receiver / d², where
 * the primes are the least angles that the slot's bounding sphere and cone allow (Conty Estevez
 * & Kulla 2018, eq. 3; pbrt-v4 LightBounds::Importance), every angle held as its cosine and sine
 * (pbrt-v4's cosSubClamped / sinSubClamped): no trigonometry. 0 where no light below can reach
 * p's hemisphere, or for an empty slot (φ = 0, cos θ_e = 1). The receiver's bound is one-sided
 * because every BSDF here reflects only (a transmissive one would take |cos|). */
inline float4 light_slot_importance(global const LightTreeNode* node, float3 p, float3 n) {
    const float4 zero = (float4)(0.0f), one = (float4)(1.0f);
    float4 dx = p.x - node->x, dy = p.y - node->y, dz = p.z - node->z; /* centre → p */
    float4 d2 = dx * dx + dy * dy + dz * dz;
    float4 r = node->radius, r2 = r * r;
    /* The distance is clamped to the bounding sphere's radius so that a point near or inside
     * the box does not get an unbounded importance. pbrt-v4 writes max(d², |diagonal|/2),
     * comparing a squared distance with a length (its scale-dependent slip); this compares
     * squares. */
    float4 inv_d2_clamped = one / max(d2, r2);
    int4 apart = d2 > zero;
    float4 inv_d = select(zero, one / sqrt(d2), apart);
    /* Every cosine and sine below is a length times 1/d, the lengths' roots taken beside d's
     * own: |d| cos θ = a · d and |d| sin θ = |a × d| = sqrt(d² − (a · d)²) for a unit a. Where
     * p is the centre (d = 0), the direction is arbitrary: θ = 0. */
    float4 along_axis = node->ax * dx + node->ay * dy + node->az * dz;
    float4 along_normal = -(n.x * dx + n.y * dy + n.z * dz);
    float4 across_axis = sqrt(max(zero, d2 - along_axis * along_axis));
    float4 across_normal = sqrt(max(zero, d2 - along_normal * along_normal));
    float4 beside_sphere = sqrt(max(zero, d2 - r2));

    /* θ_w: between the cone's axis and the direction to p; either way for two-sided lights. */
    int4 two_sided = ((uint4)(node->flags) & (uint4)(LIGHT_SLOT_TWO_SIDED, LIGHT_SLOT_TWO_SIDED << 1,
                                                     LIGHT_SLOT_TWO_SIDED << 2,
                                                     LIGHT_SLOT_TWO_SIDED << 3)) != (uint4)(0u);
    along_axis = select(along_axis, fabs(along_axis), two_sided);
    float4 cos_w = select(one, along_axis * inv_d, apart);
    float4 sin_w = across_axis * inv_d;
    /* θ_b: half-angle of the bounding sphere seen from p; the whole sphere from inside it. */
    int4 outside = d2 > r2;
    float4 sin_b = select(one, min(r * inv_d, one), outside);
    float4 cos_b = select(-one, beside_sphere * inv_d, outside);
    /* θ' = max(0, θ_w − θ_o − θ_b): the least angle between a normal and a direction to p. */
    float4 cos_o = node->cos_o, sin_o = node->sin_o;
    int4 in_cone = cos_w > cos_o;
    float4 cos_x = select(cos_w * cos_o + sin_w * sin_o, one, in_cone);
    float4 sin_x = select(sin_w * cos_o - cos_w * sin_o, zero, in_cone);
    float4 cos_p = select(cos_x * cos_b + sin_x * sin_b, one, cos_x > cos_b);

    /* At the receiver: the least angle between n and a direction toward the sphere. */
    float4 cos_i = select(one, along_normal * inv_d, apart);
    float4 sin_i = across_normal * inv_d;
    float4 cos_pi = select(cos_i * cos_b + sin_i * sin_b, one, cos_i > cos_b);
    float4 importance = node->phi * inv_d2_clamped * cos_p * cos_pi;
    return select(importance, zero, (cos_p <= node->cos_e) | (cos_pi <= zero));
}

/* The probabilities of a node's four slots at (p, n): the one computation the sampler and the
 * pmf share, so that both multiply the very same floats. A slot's bounds are tighter than its
 * parent's, so all four may have no importance where the parent had some: they are then weighed
 * by power alone (none can light p, so the choice only needs to be some choice), and the pmfs of
 * all lights sum to 1 wherever the root's slots have importance. False at the root when no
 * light can reach p, and anywhere for a non-finite importance. */
inline bool light_tree_shares(global const LightTreeNode* node, float3 p, float3 n, bool root,
                              float4* share) {
    float4 importance = light_slot_importance(node, p, n);
    float sum = (importance.x + importance.y) + (importance.z + importance.w);
    if (sum == 0.0f && !root) {
        importance = node->phi;
        sum = (importance.x + importance.y) + (importance.z + importance.w);
    }
    if (!(sum > 0.0f) || !isfinite(sum)) return false;
    *share = importance / sum;
    return true;
}

/* Component `slot` of share, by a shuffle rather than a branch on the slot. */
inline float light_slot_share(float4 share, uint slot) { return shuffle(share, (uint4)(slot)).x; }

/* Where [lo, hi) is cut between a part of share a (below) and one of share b (above), both
 * taken of the node's span: the smaller share's width is computed directly, so that both keep
 * their relative precision, and a part with a share keeps at least one value. */
inline ulong light_tree_cut(ulong lo, ulong hi, float a, float b, float span) {
    ulong width = hi - lo;
    /* Through signed 64-bit conversions (span ≤ 2^62): the hardware's, where unsigned ones may
     * be emulated. Both candidates, then a select: which share is smaller is a coin flip that
     * a branch would mispredict. */
    ulong from_a = min(width, (ulong)(long)(a * span));
    ulong from_b = width - min(width, (ulong)(long)(b * span));
    ulong t = select(from_b, from_a, (ulong)(a <= b));
    t = select(t, max(t, min(width, 1ul)), (ulong)(a > 0.0f));
    t = select(t, min(t, width - 1ul), (ulong)(b > 0.0f && width > 0ul));
    return lo + t;
}

/* A prefetch hint where the compiler has one (clang's __builtin_prefetch), else nothing. */
#if defined(__has_builtin)
#if __has_builtin(__builtin_prefetch)
#define MCRT_PREFETCH(address) __builtin_prefetch(address)
#endif
#endif
#ifndef MCRT_PREFETCH
#define MCRT_PREFETCH(address) ((void)(address))
#endif

/* Starts loading what the walk reads after `node` while its importances are computed: the
 * nodes below its inner slots (the next node is one of them) and the lights of its leaf slots
 * (the one chosen is read next, to sample a point on it). On a tree or a light array larger than
 * the cache these loads are the choice's longest waits. Hints only (MCRT_PREFETCH): nothing is
 * read; `lights` 0 or a slot's light at or past `light_count` (a punctual light) is not
 * fetched. */
inline void light_tree_prefetch_below(global const LightTreeNode* nodes,
                                      global const LightTreeNode* node,
                                      global const Light* lights, uint light_count) {
    for (uint slot = 0u; slot < LIGHT_TREE_WIDTH; ++slot) {
        uint child = node->child[slot];
        if ((node->flags & (LIGHT_SLOT_LEAF << slot)) == 0u) {
            global const char* next = (global const char*)(nodes + child);
            for (uint line = 0u; line < sizeof(LightTreeNode); line += 64u)
                MCRT_PREFETCH(next + line);
        } else if (lights != 0 && child < light_count) {
            global const char* light = (global const char*)(lights + child);
            for (uint line = 0u; line < sizeof(Light); line += 64u)
                MCRT_PREFETCH(light + line);
        }
    }
}

/* Chooses a light at (p, n) from u on the 2^-24 grid refined by u_fine (discrete.cl). The
 * number (k + u_fine)·2^-24 is held as a 62-bit integer x in [0, range), range ≤ 2^62; each
 * level cuts the range into the slots' shares (first the two pairs, then within each pair) and
 * keeps the part x falls in, rescaled: the stratification of u carries over as with CDF
 * inversion, and x / range at the leaf is uniform for the point on the light. pmf is the product
 * of the slots' probabilities: the chance of the choice up to float rounding. pmf 0: no light
 * can reach p (index is then meaningless). lights[0, light_count): the area lights, only
 * prefetched (light_tree_prefetch_below; 0 where the caller reads none). */
inline DiscreteSample sample_light_tree(global const LightTreeNode* nodes,
                                        global const Light* lights, uint light_count, float3 p,
                                        float3 n, float u, float u_fine) {
    DiscreteSample s;
    s.index = 0u;
    s.pmf = 0.0f;
    s.u_remap = 0.0f;
    global const LightTreeNode* node = nodes;
    ulong x = ((ulong)unit_to_grid(u) << 38) + (ulong)(long)(u_fine * 0x1.0p38f);
    ulong range = 1ul << 62;
    float pmf = 1.0f;
    for (uint depth = 0u; depth < MCRT_LIGHT_TREE_MAX_DEPTH; ++depth) {
        light_tree_prefetch_below(nodes, node, lights, light_count);
        float4 share;
        if (!light_tree_shares(node, p, n, depth == 0u, &share)) return s;
        float span = (float)(long)range;
        ulong middle = light_tree_cut(0ul, range, share.x + share.y, share.z + share.w, span);
        /* Both pairs' cuts, then the one x needs: no branch between dependent steps. */
        ulong left = light_tree_cut(0ul, middle, share.x, share.y, span);
        ulong right = light_tree_cut(middle, range, share.z, share.w, span);
        bool first_pair = x < middle;
        ulong cut = first_pair ? left : right;
        bool below = x < cut;
        uint slot = (first_pair ? 0u : 2u) + (below ? 0u : 1u);
        ulong lo = below ? (first_pair ? 0ul : middle) : cut;
        ulong hi = below ? cut : (first_pair ? middle : range);
        x -= lo;
        range = hi - lo;
        pmf *= light_slot_share(share, slot);
        if ((node->flags & (LIGHT_SLOT_LEAF << slot)) != 0u) {
            s.index = node->child[slot];
            s.pmf = pmf;
            s.u_remap = min((float)(long)x / (float)(long)range, 0x1.fffffep-1f);
            return s;
        }
        node = nodes + node->child[slot];
    }
    return s; /* deeper than any tree the host builds */
}

/* Probability that sample_light_tree at (p, n) returns the light whose path is `trail` over
 * `length` nodes (LightTreePath): the same products along its path. */
inline float light_tree_pmf(global const LightTreeNode* nodes, uint trail, uint length, float3 p,
                            float3 n) {
    global const LightTreeNode* node = nodes;
    float pmf = 1.0f;
    for (uint depth = 0u; depth < length; ++depth) {
        float4 share;
        if (!light_tree_shares(node, p, n, depth == 0u, &share)) return 0.0f;
        uint slot = (trail >> (2u * depth)) & 3u;
        pmf *= light_slot_share(share, slot);
        if (depth + 1u < length) node = nodes + node->child[slot];
    }
    return length == 0u ? 0.0f : pmf;
}

#endif
