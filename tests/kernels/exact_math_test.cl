/* Test entry points for kernels/core/exact_math.cl (tests/sampling/test_exact_math.cpp): each evaluates a
 * family of functions over an input buffer and writes what they return. Global sizes are 1D;
 * each entry checks its bound. */
#include "exact_math.cl"

/* Reads x[k]; writes out[k] = (exact_sinpi, exact_cospi, and exact_sincospi's sin and cos). */
kernel void sincospi_values(uint count, global const float* x, global float4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float c;
    float s = exact_sincospi(x[k], &c);
    out[k] = (float4)(exact_sinpi(x[k]), exact_cospi(x[k]), s, c);
}

/* Reads yx[k] = (y, x); writes out[k] = (exact_atan2(y, x), exact_hypot(x, y)). */
kernel void atan2_hypot_values(uint count, global const float2* yx, global float2* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float y = yx[k].x, x = yx[k].y;
    out[k] = (float2)(exact_atan2(y, x), exact_hypot(x, y));
}

/* Reads a[k].xyz, b[k].xyz and t = a[k].w; writes out[4k .. 4k + 3] = (exact_dot3(a, b),
 * exact_length3(a), exact_mix(a.x, b.x, t), 0), exact_normalize3(a), exact_cross3(a, b),
 * exact_mix3(a, b, t) (.w = 0). */
kernel void vector_values(uint count, global const float4* a, global const float4* b,
                          global float4* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float3 u = a[k].xyz, v = b[k].xyz;
    float t = a[k].w;
    out[4 * k] = (float4)(exact_dot3(u, v), exact_length3(u), exact_mix(u.x, v.x, t), 0.0f);
    out[4 * k + 1] = (float4)(exact_normalize3(u), 0.0f);
    out[4 * k + 2] = (float4)(exact_cross3(u, v), 0.0f);
    out[4 * k + 3] = (float4)(exact_mix3(u, v, t), 0.0f);
}

/* Reads abc[k] = (a, b, c); writes out[k] = a * b + c as written after exact_math.cl's
 * FP_CONTRACT OFF: two roundings, which a fused multiply-add would change. */
kernel void contraction_probe(uint count, global const float4* abc, global float* out) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    float4 v = abc[k];
    out[k] = v.x * v.y + v.z;
}
