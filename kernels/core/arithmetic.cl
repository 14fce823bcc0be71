/* One arithmetic on every device. OpenCL lets each implementation give its own last bits for the
 * built-in dot, cross, length, normalize, mix (their order of operations and fusing are the
 * vendor's) and for sinpi, cospi, atan2, hypot (a few ulp each), so an image would differ
 * between PoCL and Intel's runtime. From here on those names are mcrt's own versions
 * (exact_math.cl), made of IEEE-754 basic operations in a fixed order, in mcrt's kernels and in
 * user estimator files alike. With contraction off (shared_types.h) and division and sqrt
 * correctly rounded (-cl-fp32-correctly-rounded-divide-sqrt, host/cl/program.cpp), every
 * operation the kernels use then rounds as IEEE-754 says (docs/DESIGN.md, "Determinism").
 * Built-ins left to the vendor: none that mcrt's kernels call; a user file calling exp, log,
 * pow, sin, cos, ... gets the vendor's. The vector forms take float3 (and mix any type). */
#ifndef MCRT_ARITHMETIC_CL
#define MCRT_ARITHMETIC_CL

#include "exact_math.cl"

#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define MCRT_HAVE_FP64 1
#endif

/* v / |v| for any finite v ≠ 0: scaled by a power of two (exact) first where |v|² would
 * overflow or underflow, as the built-in normalize does; 0 stays 0. */
inline float3 mcrt_normalize(float3 v) {
    float l2 = exact_dot3(v, v);
    if (l2 > 0x1.0p-100f && l2 < 0x1.0p100f) return v * (1.0f / sqrt(l2));
    float m = fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z)));
    if (!(m > 0.0f) || !(m <= MAXFLOAT)) return v; /* zero, or not finite */
    float3 s = ldexp(v, -ilogb(m));                 /* largest component in [1, 2) */
    return s * (1.0f / sqrt(exact_dot3(s, s)));
}

/* #undef first: an implementation's header may define these as macros itself (PoCL's do). */
#undef dot
#define dot(a, b) exact_dot3(a, b)
#undef cross
#define cross(a, b) exact_cross3(a, b)
#undef length
#define length(v) exact_length3(v)
#undef normalize
#define normalize(v) mcrt_normalize(v)
#undef mix
#define mix(a, b, t) ((a) + ((b) - (a)) * (t))
#undef sinpi
#define sinpi(x) exact_sinpi(x)
#undef cospi
#define cospi(x) exact_cospi(x)
#undef atan2
#define atan2(y, x) exact_atan2(y, x)
#undef hypot
#define hypot(x, y) exact_hypot(x, y)

#ifdef MCRT_HAVE_FP64
/* The double forms surface_point uses, in the same fixed order. */
inline double mcrt_dot_double3(double3 a, double3 b) {
    return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
inline double3 mcrt_cross_double3(double3 a, double3 b) {
    return (double3)(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
#endif

#endif
