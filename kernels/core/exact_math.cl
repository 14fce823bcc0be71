/* Elementary functions that give the same bits on every OpenCL implementation. The built-ins
 * (sin, cospi, atan2, hypot, ...) may be off by a few ulp and differ from vendor to vendor, and
 * dot, length, normalize and cross sum in a vendor-defined order, so an image rendered with
 * them differs in its last bits between PoCL and Intel's runtime. These are written with
 * IEEE-754 basic operations only: +, −, ×, /, sqrt (correctly rounded under
 * -cl-fp32-correctly-rounded-divide-sqrt), fma (correctly rounded by the spec), and exact ones
 * (fabs, copysign, rint, comparisons, integer ops), each in a fixed order. Constants are hex
 * literals: a decimal one may round either way (C99 6.4.4.2). They need a build without
 * -cl-fast-relaxed-math, -cl-unsafe-math-optimizations or -cl-mad-enable, which would reorder
 * or fuse the error-free sums below.
 *
 * Largest errors measured, against long double: exact_sinpi 0.72 ulp (0.96 at denormal x),
 * exact_cospi 0.72, exact_atan2 0.70 (0.86 where y/x nears the underflow threshold),
 * exact_hypot 1.02 (bound 1.25) — sinpi's and cospi's kernels on every float of [0, 1/4],
 * atan2 on every ratio of [0, 1] in each octant and on 2e8 random pairs, hypot on 2e8; and
 * tests/sampling/test_exact_math.cpp on every device. */
#ifndef MCRT_EXACT_MATH_CL
#define MCRT_EXACT_MATH_CL

/* a * b + c is two roundings, never a fused one left to the compiler: the OpenCL C default is
 * ON (6.10), and PoCL and Intel's runtime do fuse. The pragma holds to the end of the program,
 * past this file. */
#pragma OPENCL FP_CONTRACT OFF

/* ---- sin(πx), cos(πx) ------------------------------------------------------------------ */

/* π = EXACT_PI_HI + EXACT_PI_LO to 2^-48. */
#define EXACT_PI_HI 0x1.921fb6p+1f
#define EXACT_PI_LO -0x1.777a5cp-24f

/* sin(πf) for |f| ≤ 1/4: f·(π + z·P(z)), z = f², P minimax for relative error (Remez in
 * double, coefficients rounded to float one at a time, the higher ones refitted; 0.07 ulp before
 * the evaluation's roundings). π·f rounds once: fma with π split in two. */
inline float exact_sinpi_quarter(float f) {
    float z = f * f;
    float p = fma(z, fma(z, -0x1.2db5cep-1f, 0x1.465facp+1f), -0x1.4abbbep+2f);
    return fma(f, EXACT_PI_HI, f * fma(z, p, EXACT_PI_LO));
}

/* cos(πf) for |f| ≤ 1/4: 1 + B1·z + z²·R(z), z = f², B1 = −π²/2 rounded, R minimax for
 * relative error with B1 fixed (Remez as above; 0.008 ulp). z's rounding is kept (z_lo, exact by
 * fma) and so is that of 1 + B1·z, to 2^-24 of itself, by a second fma (the error-free
 * transforms of Muller et al., "Handbook of Floating-Point Arithmetic"): only the final sum
 * rounds at the result's ulp. */
inline float exact_cospi_quarter(float f) {
    const float b1 = -0x1.3bd3ccp+2f;
    float z = f * f, z_lo = fma(f, f, -z);
    float r = fma(z, fma(z, 0x1.d4f7eep-3f, -0x1.55b2b6p+0f), 0x1.03c1b0p+2f);
    float c_hi = fma(z, b1, 1.0f);
    float c_err = fma(z, b1, 1.0f - c_hi); /* 1 − c_hi is exact (Sterbenz): c_hi in [0.7, 1] */
    return c_hi + fma(z * z, r, fma(z_lo, b1, c_err));
}

/* sin(πx), returning cos(πx) in *c, for any x (NaN for ±∞ and NaN). x = n/2 + f, |f| ≤ 1/4,
 * exactly: in turns the additive reduction needs no Cody & Waite split of π, unlike sin(x).
 * The quadrant n mod 4 picks ±sin(πf) or ±cos(πf). Exact 0 and ±1 at integers and
 * half-integers: sin(π·±n) = ±0 and cos(π(n + 1/2)) = +0 (IEEE 754-2019 9.2.1); sin is odd and
 * cos even bit for bit. */
inline float exact_sincospi(float x, float* c) {
    float ax = fabs(x);
    bool reducible = ax < 0x1p24f;              /* from 2^24 up, every float is an even integer */
    float k = reducible ? rint(ax + ax) : 0.0f; /* n, exact: ax + ax < 2^25 */
    /* exact: a multiple of ulp(ax) with |f| ≤ 1/4 ≤ ax; NaN for ±∞ and NaN */
    float f = reducible ? ax - 0.5f * k : ax * 0.0f;
    int quadrant = (int)k & 3;
    float s = exact_sinpi_quarter(f), co = exact_cospi_quarter(f);
    float sin_ax = quadrant == 0 ? s : quadrant == 1 ? co : quadrant == 2 ? -s : -co;
    float cos_ax = quadrant == 0 ? co : quadrant == 1 ? -s : quadrant == 2 ? -co : s;
    *c = cos_ax == 0.0f ? 0.0f : cos_ax;
    float sin_x = x < 0.0f ? -sin_ax : sin_ax;
    return sin_x == 0.0f ? copysign(0.0f, x) : sin_x;
}

inline float exact_sinpi(float x) {
    float c;
    return exact_sincospi(x, &c);
}

inline float exact_cospi(float x) {
    float c;
    exact_sincospi(x, &c);
    return c;
}

/* ---- atan2 ------------------------------------------------------------------------------- */

/* π/4 = EXACT_PI_4_HI + EXACT_PI_4_LO to 2^-50. */
#define EXACT_PI_4_HI 0x1.921fb6p-1f
#define EXACT_PI_4_LO -0x1.777a5cp-26f

/* atan(u)/u − 1 = z·P(z) for |u| ≤ 1/2, z = u², P minimax for relative error (Remez as for
 * sinpi; 0.005 ulp), Horner. */
inline float exact_atan_tail(float z) {
    float p = 0x1.3fd554p-5f;
    p = fma(z, p, -0x1.480d40p-4f);
    p = fma(z, p, 0x1.c07268p-4f);
    p = fma(z, p, -0x1.245030p-3f);
    p = fma(z, p, 0x1.999744p-3f);
    p = fma(z, p, -0x1.555552p-2f);
    return z * p;
}

/* The angle of (x, y) in [−π, π], with C99's conventions (F.9.1.4): atan2(±0, +0) = ±0,
 * atan2(±0, −0) = ±π, atan2(y ≠ 0, ±0) = ±π/2, atan2(±∞, ±∞) = ±π/4 or ±3π/4; NaN in, NaN out.
 *
 * With lo ≤ hi the smaller and larger of |x|, |y|, the octant makes the angle base ± θ, base
 * 0, π/2 or π, θ = atan(lo/hi) in [0, π/4]. Past lo/hi = 1/2, θ = π/4 + atan(u) with
 * u = (lo − hi)/(lo + hi) in [−1/3, 0], the numerator exact (Sterbenz) and the denominator's
 * rounding kept (Dekker's fast two-sum); below, u = lo/hi. (The additive reduction of Cody &
 * Waite's atan, "Software Manual for the Elementary Functions", by π/4 here.) The division's
 * rounding is recovered as δ: atan(n/d) − atan(u) = atan((n − u·d)/(d + u·n)) ≈ δ =
 * (n − u·d)/(d + u·n), n − u·d exact by fma. k·π/4 ± u is summed exactly (fast two-sum again),
 * so that only the last addition rounds at the result's ulp. */
inline float exact_atan2(float y, float x) {
    float ax = fabs(x), ay = fabs(y);
    bool steep = ay > ax, behind = signbit(x);
    float lo = steep ? ax : ay, hi = steep ? ay : ax;
    /* Powers of two (exact): lo + hi must not overflow, and the residual lo − u·hi below must
     * not underflow where it matters (lo/hi > 2^-40) */
    float scale = hi > 0x1p126f ? 0x1p-2f : hi < 0x1p-64f ? 0x1p64f : 1.0f;
    lo *= scale;
    hi *= scale;
    bool finite = hi > 0.0f && hi <= 0x1.fffffep127f; /* neither 0/0 nor ∞/∞ below */
    bool diagonal = lo + lo >= hi && hi > 0.0f;       /* θ in [atan(1/2), π/4] */
    float n = diagonal ? lo - hi : lo;
    float d = diagonal ? lo + hi : hi;
    float d_err = diagonal ? lo - (d - hi) : 0.0f; /* d + d_err = lo + hi exactly */
    float u = finite ? n / d : 0.0f;
    float delta = finite ? (fma(-u, d, n) - u * d_err) / fma(u, n, d) : 0.0f;
    /* angle = k·π/4 + sign·(atan(u) + δ), k = 0 … 4 */
    bool minus = steep != behind;
    int k = (steep ? 2 : behind ? 4 : 0) + (diagonal ? (minus ? -1 : 1) : 0);
    float kf = (float)k;
    float base_hi = kf * EXACT_PI_4_HI;
    float base_lo = fma(kf, EXACT_PI_4_HI, -base_hi) + kf * EXACT_PI_4_LO;
    float signed_u = minus ? -u : u, signed_delta = minus ? -delta : delta;
    float sum = base_hi + signed_u;
    float sum_err = (base_hi - sum) + signed_u; /* exact: base_hi ≥ π/4 > |u|, or 0 */
    float low = fma(signed_u, exact_atan_tail(u * u), signed_delta + (sum_err + base_lo));
    float angle = copysign(sum + low, y);
    return ax == ax && ay == ay ? angle : x + y;
}

/* ---- hypot ------------------------------------------------------------------------------- */

/* sqrt(x² + y²) without overflow or underflow in between: the larger magnitude is scaled by a
 * power of two (exact) into [2^-59, 2^58] first, and the sum of squares is one fma. Within
 * 0.5 + 0.75 ulp: the fma's and lo²'s roundings, halved by sqrt, and sqrt's own; exactly |x|
 * when y = 0, since sqrt(RN(x²)) = |x|. */
inline float exact_hypot(float x, float y) {
    float ax = fabs(x), ay = fabs(y);
    float hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
    float scale = hi > 0x1p50f ? 0x1p-70f : hi < 0x1p-50f ? 0x1p90f : 1.0f;
    float unscale = hi > 0x1p50f ? 0x1p70f : hi < 0x1p-50f ? 0x1p-90f : 1.0f;
    hi *= scale;
    lo *= scale;
    return sqrt(fma(hi, hi, lo * lo)) * unscale;
}

/* ---- exp2 -------------------------------------------------------------------------------- */

/* 2^x = 2^k · 2^f with k = rint(x) and f = x − k in [−1/2, 1/2] (both exact); 2^f = e^(f ln 2) by
 * its Taylor series to degree 7, whose remainder is below 6e-9 (0.1 ulp), in Horner form with
 * fma; then 2^k by ldexp (exact, or rounded once into the denormals). 0 for x ≤ −150, +∞ for
 * x ≥ 128, NaN for NaN. What Beer–Lambert attenuation needs (kernels/materials/dielectric.cl). */
inline float exact_exp2(float x) {
    if (x != x) return x;
    if (x <= -150.0f) return 0.0f;
    if (x >= 128.0f) return INFINITY;
    float k = rint(x);
    float f = x - k;
    float p = fma(f, 0x1.ffcbfcp-17f, 0x1.430912p-13f);
    p = fma(f, p, 0x1.5d87fep-10f);
    p = fma(f, p, 0x1.3b2ab6p-7f);
    p = fma(f, p, 0x1.c6b08ep-5f);
    p = fma(f, p, 0x1.ebfbe0p-3f);
    p = fma(f, p, 0x1.62e430p-1f);
    p = fma(f, p, 1.0f);
    return ldexp(p, (int)k);
}

/* ---- Vectors ----------------------------------------------------------------------------- */

/* (a.x·b.x + a.y·b.y) + a.z·b.z, every product and sum rounded, in this order. */
inline float exact_dot3(float3 a, float3 b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }

/* sqrt(exact_dot3(v, v)): unscaled, so components beyond ~1.8e19 overflow and below ~1e-19
 * underflow (exact_hypot scales, for two components). */
inline float exact_length3(float3 v) { return sqrt(exact_dot3(v, v)); }

/* v · (1 / |v|): one division and three products, rather than three divisions; NaN for the
 * zero vector. */
inline float3 exact_normalize3(float3 v) { return v * (1.0f / sqrt(exact_dot3(v, v))); }

/* a × b, each component a rounded product minus a rounded product. */
inline float3 exact_cross3(float3 a, float3 b) {
    float3 c;
    c.x = a.y * b.z - a.z * b.y;
    c.y = a.z * b.x - a.x * b.z;
    c.z = a.x * b.y - a.y * b.x;
    return c;
}

/* a + (b − a)·t: exactly a at t = 0 (b at t = 1 only when b − a is exact). */
inline float exact_mix(float a, float b, float t) { return a + (b - a) * t; }

inline float3 exact_mix3(float3 a, float3 b, float t) { return a + (b - a) * t; }

#endif /* MCRT_EXACT_MATH_CL */
