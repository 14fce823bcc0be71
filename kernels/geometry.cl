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

/* Wächter & Binder 2019, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing
 * Gems, ch. 6): move p along n by a few ulps, scaled to p's magnitude, not by a fixed epsilon. */
inline float offset_component(float p, float n) {
    const float origin = 1.0f / 32.0f;
    const float float_scale = 1.0f / 65536.0f;
    const float int_scale = 256.0f;
    int of = (int)(int_scale * n);
    float p_i = as_float(as_int(p) + (p < 0.0f ? -of : of));
    return fabs(p) < origin ? p + float_scale * n : p_i;
}

/* n must be the geometric normal on the side the new ray leaves from. */
inline float3 offset_ray_origin(float3 p, float3 n) {
    return (float3)(offset_component(p.x, n.x), offset_component(p.y, n.y),
                    offset_component(p.z, n.z));
}

#endif
