/* Points, normals and rays. */
#ifndef MCRT_GEOMETRY_CL
#define MCRT_GEOMETRY_CL

/* A ray with what the watertight test and the slab test need precomputed. */
typedef struct {
    float3 org;
    float3 dir;
    float3 inv_dir; /* finite: zero components are replaced by ±1e-20 before inverting */
    uint4 shear_axes; /* kx, ky, kz, 3 (Woop et al. 2013) */
    float3 shear;     /* Sx, Sy, Sz */
} Ray;

inline Ray make_ray(float3 org, float3 dir) {
    Ray r;
    r.org = org;
    r.dir = dir;
    const float tiny = 1e-20f;
    float3 d = (float3)(fabs(dir.x) < tiny ? copysign(tiny, dir.x) : dir.x,
                        fabs(dir.y) < tiny ? copysign(tiny, dir.y) : dir.y,
                        fabs(dir.z) < tiny ? copysign(tiny, dir.z) : dir.z);
    r.inv_dir = 1.0f / d;
    /* Woop, Benthin, Wald 2013, "Watertight Ray/Triangle Intersection", sec. 3: the axis where
     * the direction is largest becomes z; swap x and y to keep the winding when dir.z < 0. */
    float3 a = fabs(dir);
    uint kz = (a.x >= a.y && a.x >= a.z) ? 0u : (a.y >= a.z ? 1u : 2u);
    uint kx = kz == 2u ? 0u : kz + 1u;
    uint ky = kx == 2u ? 0u : kx + 1u;
    float dz = kz == 0u ? dir.x : (kz == 1u ? dir.y : dir.z);
    if (dz < 0.0f) {
        uint t = kx;
        kx = ky;
        ky = t;
    }
    r.shear_axes = (uint4)(kx, ky, kz, 3u);
    float4 dp = shuffle((float4)(dir, 0.0f), r.shear_axes);
    r.shear = (float3)(dp.x / dp.z, dp.y / dp.z, 1.0f / dp.z);
    return r;
}

/* γ(n) = nε / (1 − nε), ε = 2^-24: a bound on the relative error of n successive float roundings
 * (PBRT 4th ed., sec. 6.8.1, "Floating-point arithmetic"). A constant expression. */
#define MCRT_GAMMA(n) ((float)(n) * 0x1.0p-24f / (1.0f - (float)(n) * 0x1.0p-24f))

/* Per-component bound on the rounding error of a point p0 + b1·e1 + b2·e2 computed in float
 * from its triangle's vertices (e1 = p1 − p0 and e2 = p2 − p0 rounded once each), given the
 * products b1·e1 and b2·e2: each of the three terms carries at most four roundings (the edge,
 * the product, two sums; a fused multiply-add only removes one), so γ(5)·(|p0| + |b1·e1| +
 * |b2·e2|) bounds it (PBRT 4th ed., sec. 6.8.5, "Bounding intersection point error", for the
 * form b0·p0 + b1·p1 + b2·p2). What it bounds is the distance from the triangle's own plane:
 * the barycentrics' errors move the point within that plane only. It grows with the vertices'
 * magnitudes, not the point's: a point near the origin on a 2 km floor is as uncertain as the
 * floor's corners. */
inline float3 interpolation_error(float3 p0, float3 b1_e1, float3 b2_e2) {
    return MCRT_GAMMA(5) * (fabs(p0) + fabs(b1_e1) + fabs(b2_e2));
}

/* Each component of x moved to the next float in the direction of the sign of `toward`'s, and
 * left where that is 0: the bits of a nonzero float step away from zero by +1 or toward it by
 * −1; a zero steps to the least denormal of that sign (nextafter for finite x, by the bits). */
inline float3 float_step(float3 x, float3 toward) {
    int3 away = (toward > (float3)(0.0f)) == (x >= (float3)(0.0f));
    float3 moved = as_float3(as_int3(x) + select((int3)(-1), (int3)(1), away));
    moved = select(moved, copysign((float3)(0x1.0p-149f), toward), x == (float3)(0.0f));
    return select(x, moved, toward != (float3)(0.0f));
}

/* The origin of a ray leaving the point p (per-component error bound p_error) on the side of
 * n, its surface's unit geometric normal on that side: p moved along n by d = |n|·p_error,
 * which puts every point p_error allows on that side of the surface's plane, then each moved
 * component rounded one float further from p, so that the sum's own rounding cannot bring it
 * back (PBRT 4th ed., sec. 6.8.6, "Robust spawned ray origins", OffsetRayOrigin). Where the
 * point is exact (p_error 0, as on a floor at y = 0), the origin stays on the plane: the
 * traversal skips the triangle the ray leaves, and the intersection test accepts only
 * distances beyond its own rounding (intersect.cl), so neither the triangle nor a coplanar
 * neighbour is hit again. */
inline float3 offset_ray_origin(float3 p, float3 p_error, float3 n) {
    float d = dot(fabs(n), p_error);
    float3 offset = d * n;
    float3 po = p + offset;
    return float_step(po, offset);
}

#endif
