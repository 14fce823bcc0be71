/* Watertight ray–triangle intersection (Woop, Benthin, Wald 2013, JCGT 2(1)): no ray passes
 * between two triangles sharing an edge, whatever the rounding. */
#ifndef MCRT_INTERSECT_CL
#define MCRT_INTERSECT_CL

#include "geometry.cl"

/* The edge functions of a shared edge must round identically in both triangles: a fused
 * multiply-add in one and not the other would open cracks (Woop et al. 2013, sec. 4). Contraction
 * is off in every program (shared_types.h); said again here, where it matters twice. */
#pragma OPENCL FP_CONTRACT OFF


/* The ray as the four-lane test reads it: its origin on the permuted axes kx, ky, kz and its
 * shear, splatted, and the permutation as indices into TrianglePacket.v. */
typedef struct {
    float4 org_x, org_y, org_z;
    float4 shear_x, shear_y, shear_z;
    uint kx, ky, kz;
} PacketRay;

inline PacketRay make_packet_ray(const Ray* r) {
    PacketRay q;
    float4 o = shuffle((float4)(r->org, 0.0f), r->shear_axes);
    q.org_x = (float4)(o.x);
    q.org_y = (float4)(o.y);
    q.org_z = (float4)(o.z);
    q.shear_x = (float4)(r->shear.x);
    q.shear_y = (float4)(r->shear.y);
    q.shear_z = (float4)(r->shear.z);
    q.kx = r->shear_axes.x;
    q.ky = r->shear_axes.y;
    q.kz = r->shear_axes.z;
    return q;
}

/* Bound δt on the rounding error of the distance t that the test below computes, for lanes
 * that hit (PBRT 4th ed. sec. 6.8.7, "Avoiding intersections behind ray origins", in a looser
 * closed form): from the magnitudes of the translated, permuted and sheared vertices — max_zt of
 * z scaled by 1/d_z (in t), max_z of z before it, max_xt and max_yt of x and y (in length) — and
 * 1/det. pbrt's bound is 3(γ3 e z + δe z + δz e)/|det| with e = max |edge function| ≤ |det| on
 * a hit lane, δz = γ3 z, δe = 2(γ2 x y + δy x + δx y), δx = γ5(x + Z), δy = γ5(y + Z), so
 * δt ≤ z (6γ3 + 6((γ2 + 2γ5) x y + γ5 Z (x + y))/|det|), which drops e and a few operations.
 * pbrt puts the scaled z in δx and δy; the shear's error is bounded by the unscaled Z
 * (|S_x|, |S_y| ≤ 1), and the scaled one is 1/|d| times too large for a ray whose direction is
 * not unit (a shadow ray's spans its segment): every hit of a short segment would fall within
 * its own "error". */
inline float4 t_rounding_bound(float4 max_zt, float4 max_z, float4 max_xt, float4 max_yt,
                               float4 inv_det) {
    float4 half_delta_e = (MCRT_GAMMA(2) + 2.0f * MCRT_GAMMA(5)) * max_xt * max_yt +
                          MCRT_GAMMA(5) * max_z * (max_xt + max_yt);
    return max_zt * (6.0f * MCRT_GAMMA(3) + 6.0f * half_delta_e * fabs(inv_det));
}

/* A packet's vertices translated to the ray origin and permuted (z the dominant axis), with x
 * and y sheared (Woop et al. 2013, sec. 3); z is not yet scaled by 1/d_z. */
typedef struct {
    float4 ax, ay, bx, by, cx, cy;
    float4 a_z, b_z, c_z;
} ShearedPacket;

inline __attribute__((always_inline)) ShearedPacket shear_packet(const PacketRay* q,
                                                                 global const TrianglePacket* pk) {
    global const float4* v = pk->v;
    ShearedPacket s;
    s.a_z = v[q->kz] - q->org_z;
    s.b_z = v[3u + q->kz] - q->org_z;
    s.c_z = v[6u + q->kz] - q->org_z;
    s.ax = (v[q->kx] - q->org_x) - q->shear_x * s.a_z;
    s.ay = (v[q->ky] - q->org_y) - q->shear_y * s.a_z;
    s.bx = (v[3u + q->kx] - q->org_x) - q->shear_x * s.b_z;
    s.by = (v[3u + q->ky] - q->org_y) - q->shear_y * s.b_z;
    s.cx = (v[6u + q->kx] - q->org_x) - q->shear_x * s.c_z;
    s.cy = (v[6u + q->ky] - q->org_y) - q->shear_y * s.c_z;
    return s;
}

/* t_rounding_bound of the four lanes of a sheared packet, az..cz its z scaled by 1/d_z. */
inline float4 packet_t_rounding_bound(const ShearedPacket* s, float4 az, float4 bz, float4 cz,
                                      float4 inv_det) {
    return t_rounding_bound(max(fabs(az), max(fabs(bz), fabs(cz))),
                            max(fabs(s->a_z), max(fabs(s->b_z), fabs(s->c_z))),
                            max(fabs(s->ax), max(fabs(s->bx), fabs(s->cx))),
                            max(fabs(s->ay), max(fabs(s->by), fabs(s->cy))), inv_det);
}

/* The watertight test on the four triangles of a packet at once, each lane doing exactly the
 * operations of the scalar test of Woop et al. in the same order (so a lane's answer does not
 * depend on its packet): translate to the ray origin, permute so that z is the dominant axis,
 * shear (sec. 3); scaled barycentrics as 2D edge functions, recomputed in double when one is an
 * exact zero, which may be a rounding artefact on a shared edge; the scaled hit distance compared
 * before dividing. Returns a lane mask (-1 where a used lane not set in `skip` is hit with t in
 * (t_min, t_max)) and the lanes' t and barycentrics b1, b2 of vertices 1 and 2. With `bounded`
 * (occlusion queries) a hit must also lie beyond its own rounding bound δt at both ends,
 * t in (δt, t_max − δt): a ray leaving a surface cannot then hit that surface's plane again
 * however large its triangles, nor a shadow ray the light's plane it ends at. The closest hit
 * checks its one winner instead (bvh_closest_hit). Where a lane is hit, `delta` receives every
 * lane's δt, from which the closest hit bounds how far a box holding a tie may begin. Lanes in
 * `skip` are the triangle a ray leaves: a flat triangle cannot be hit again by a ray leaving it.
 * With -D MCRT_SINGLE_SIDED a lane marked MCRT_TRIANGLE_CULLED is not hit from behind, in every
 * query alike. Forced inline: PoCL's inliner prices it just over its threshold (565 against 562)
 * and called it, which cost the closest hit about 10% (docs/BENCHMARKS.md). */
inline __attribute__((always_inline)) int4 intersect_packet(const PacketRay* q,
                                                            global const TrianglePacket* pk,
                                                            float t_min, float t_max, int4 skip,
                                                            bool bounded, float4* t_hit,
                                                            float4* b1, float4* b2,
                                                            float4* delta) {
    ShearedPacket s = shear_packet(q, pk);
    float4 ax = s.ax, ay = s.ay, bx = s.bx, by = s.by, cx = s.cx, cy = s.cy;

    float4 u = cx * by - cy * bx;
    float4 w_ = bx * ay - by * ax;
    float4 v_ = ax * cy - ay * cx;
    int4 used = (as_int4(vload4(0, pk->index)) != (int4)(-1)) & ~skip;
#ifdef MCRT_HAVE_FP64
    int4 zero = used & ((u == 0.0f) | (v_ == 0.0f) | (w_ == 0.0f));
    if (any(zero)) {
        double4 dax = convert_double4(ax), day = convert_double4(ay);
        double4 dbx = convert_double4(bx), dby = convert_double4(by);
        double4 dcx = convert_double4(cx), dcy = convert_double4(cy);
        u = select(u, convert_float4(dcx * dby - dcy * dbx), zero);
        v_ = select(v_, convert_float4(dax * dcy - day * dcx), zero);
        w_ = select(w_, convert_float4(dbx * day - dby * dax), zero);
    }
#endif
    int4 negative = (u < 0.0f) | (v_ < 0.0f) | (w_ < 0.0f);
    int4 positive = (u > 0.0f) | (v_ > 0.0f) | (w_ > 0.0f);
    float4 det = u + v_ + w_;
    int4 hit = used & ~(negative & positive) & (det != 0.0f);
#if defined(MCRT_SINGLE_SIDED)
    /* A single-sided lane is hit from its front only: det > 0 where the ray meets the
     * counter-clockwise side (glTF 2.0 sec. 3.9.2, back-face culling; Woop et al. 2013, sec. 3,
     * BACKFACE_CULLING; the swap of x and y for dir.z < 0 keeps the sign). */
    hit &= ~((as_int4(vload4(0, pk->index)) < (int4)(0)) & (det < 0.0f));
#endif
    if (!any(hit)) return hit;

    float4 az = q->shear_z * s.a_z, bz = q->shear_z * s.b_z, cz = q->shear_z * s.c_z;
    float4 t_scaled = u * az + v_ * bz + w_ * cz;
    float4 inv_det = 1.0f / det;
    float4 t = t_scaled * inv_det;
    *t_hit = t;
    *b1 = v_ * inv_det;
    *b2 = w_ * inv_det;
    hit &= (t > (float4)(t_min)) & (t < (float4)(t_max));
    if (!any(hit)) return hit;

    float4 delta_t = packet_t_rounding_bound(&s, az, bz, cz, inv_det);
    *delta = delta_t;
    if (!bounded) return hit;
    return hit & (t > delta_t) & (t < (float4)(t_max) - delta_t);
}

/* δt of lane `lane` of a packet for the ray (t_rounding_bound), with the test's own arithmetic. */
inline float lane_t_rounding_bound(const PacketRay* q, global const TrianglePacket* pk,
                                   uint lane) {
    ShearedPacket s = shear_packet(q, pk);
    float4 det = (s.cx * s.by - s.cy * s.bx) + (s.ax * s.cy - s.ay * s.cx) +
                 (s.bx * s.ay - s.by * s.ax);
    float4 d = packet_t_rounding_bound(&s, q->shear_z * s.a_z, q->shear_z * s.b_z,
                                       q->shear_z * s.c_z, 1.0f / det);
    return lane == 0u ? d.x : lane == 1u ? d.y : lane == 2u ? d.z : d.w;
}

#endif
