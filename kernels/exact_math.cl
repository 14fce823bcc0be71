/* Elementary functions that give the same bits on every OpenCL implementation. The built-ins
 * (sin, cospi, atan2, hypot, ...) may be off by a few ulp and differ from vendor to vendor, and
 * dot, length, normalize and cross sum in a vendor-defined order, so an image rendered with
 * them differs in its last bits between PoCL and Intel's runtime. These are written with
 * IEEE-754 basic operations only: +, −, ×, /, sqrt (correctly rounded under
 * -cl-fp32-correctly-rounded-divide-sqrt), fma (correctly rounded by the spec), and exact ones
 * (fabs, copysign, rint, comparisons, integer ops), each in a fixed order. Constants are hex
 * literals: a decimal one may round either way (C99 6.4.4.2). Accuracy on all finite floats:
 * tests/test_exact_math.cpp. */
#ifndef MCRT_EXACT_MATH_CL
#define MCRT_EXACT_MATH_CL

/* a * b + c is two roundings, never a fused one left to the compiler (OpenCL C 6.10 defaults
 * FP_CONTRACT to ON). The pragma holds to the end of the program, past this file. */
#pragma OPENCL FP_CONTRACT OFF

/* ---- sin(πx), cos(πx) ------------------------------------------------------------------ */

/* π = EXACT_PI_HI + EXACT_PI_LO to 2^-48. */
#define EXACT_PI_HI 0x1.921fb6p+1f
#define EXACT_PI_LO -0x1.777a5cp-24f

/* sin(πf) for |f| ≤ 1/4: f·(π + z·P(z)), z = f², P minimax for relative error (Remez, fitted
 * in double; max 0.07 ulp before rounding). π·f is one rounding: fma with π split in two. */
inline float exact_sinpi_quarter(float f) {
    float z = f * f;
    float p = fma(z, fma(z, -0x1.2db5cep-1f, 0x1.465facp+1f), -0x1.4abbbep+2f);
    return fma(f, EXACT_PI_HI, f * fma(z, p, EXACT_PI_LO));
}

/* cos(πf) for |f| ≤ 1/4: 1 + B1·z + z²·R(z), z = f², B1 = −π²/2 rounded, R minimax for
 * relative error with B1 fixed (Remez, fitted in double; max 0.008 ulp before rounding). 1 + B1·z
 * is one fma whose rounding error is recovered by a second (Muller, "Elementary Functions",
 * error-free transforms), so that only the final sum rounds at the result's ulp. */
inline float exact_cospi_quarter(float f) {
    const float b1 = -0x1.3bd3ccp+2f;
    float z = f * f, z_lo = fma(f, f, -z);
    float r = fma(z, fma(z, 0x1.d4f7eep-3f, -0x1.55b2b6p+0f), 0x1.03c1b0p+2f);
    float c_hi = fma(z, b1, 1.0f);
    float c_err = fma(z, b1, 1.0f - c_hi); /* 1 − c_hi is exact (Sterbenz): c_hi in [0.7, 1] */
    return c_hi + fma(z * z, r, fma(z_lo, b1, c_err));
}

/* sin(πx), returning cos(πx) in *c, for any finite x (Muller, "Elementary Functions", 11.1:
 * reduction by multiples of 1/2 is exact for sinpi). x = n/2 + f, |f| ≤ 1/4, then the
 * quadrant n mod 4 picks ±sin(πf) or ±cos(πf). Exact 0 and ±1 at integers and half-integers;
 * sin(π·±n) = ±0 and cos(π(n + 1/2)) = +0 (IEEE 754-2019 9.2.1); sin is odd, cos even. */
inline float exact_sincospi(float x, float* c) {
    float ax = fabs(x);
    ax = ax < 0x1p24f ? ax : 0.0f; /* every float from 2^24 up is an even integer */
    float k = rint(ax + ax);       /* n, exact: ax + ax < 2^25 */
    float f = ax - 0.5f * k;       /* exact: a multiple of ulp(ax), |f| ≤ 1/4 ≤ ax */
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

/* π/2 = EXACT_PI_2_HI + EXACT_PI_2_LO to 2^-49. */
#define EXACT_PI_2_HI 0x1.921fb6p+0f
#define EXACT_PI_2_LO -0x1.777a5cp-25f

/* atan(q)/q − 1 = z·P(z) for q in [0, 1], z = q², P minimax for relative error (Remez, fitted
 * in double; max 0.05 ulp before rounding), Horner. */
inline float exact_atan_tail(float z) {
    float p = -0x1.d32f3cp-10f;
    p = fma(z, p, 0x1.64117ep-7f);
    p = fma(z, p, -0x1.fd7014p-6f);
    p = fma(z, p, 0x1.da24e0p-5f);
    p = fma(z, p, -0x1.580816p-4f);
    p = fma(z, p, 0x1.c08c1ap-4f);
    p = fma(z, p, -0x1.242084p-3f);
    p = fma(z, p, 0x1.9991e4p-3f);
    p = fma(z, p, -0x1.55553ep-2f);
    return z * p;
}

/* The angle of (x, y) in [−π, π] for finite x, y, with C99's conventions (F.9.1.4):
 * atan2(±0, +0) = ±0, atan2(±0, −0) = ±π, atan2(y ≠ 0, ±0) = ±π/2. With q = lo/hi of |x|, |y|,
 * the octant makes the angle base ± atan(q), base 0, π/2 or π. The division's rounding is
 * recovered: atan(lo/hi) − atan(q) = atan(δ) ≈ δ, δ = (lo − q·hi)/(hi + q·lo), the numerator
 * exact by fma; base + q is summed exactly (Dekker's fast two-sum), so only the last addition
 * rounds at the result's ulp. */
inline float exact_atan2(float y, float x) {
    float ax = fabs(x), ay = fabs(y);
    bool steep = ay > ax, behind = signbit(x);
    float lo = steep ? ax : ay, hi = steep ? ay : ax;
    /* lo < hi ≤ FLT_MAX: no 0/0 or ∞/∞ (lo = hi gives q = 1 or 0, exact) */
    bool ordinary = lo < hi && hi <= 0x1.fffffep127f;
    float q = ordinary ? lo / hi : hi == 0.0f ? 0.0f : lo == hi ? 1.0f : 0.0f;
    float delta = ordinary ? fma(-q, hi, lo) / fma(q, lo, hi) : 0.0f;
    float base_hi = steep ? EXACT_PI_2_HI : behind ? EXACT_PI_HI : 0.0f;
    float base_lo = steep ? EXACT_PI_2_LO : behind ? EXACT_PI_LO : 0.0f;
    float signed_q = steep != behind ? -q : q; /* angle = base + signed atan(q + ...) */
    float sum = base_hi + signed_q;
    float sum_err = (base_hi - sum) + signed_q; /* exact: |base_hi| ≥ q or base_hi = 0 */
    float signed_delta = steep != behind ? -delta : delta;
    float low = fma(signed_q, exact_atan_tail(q * q), signed_delta + (sum_err + base_lo));
    return copysign(sum + low, y);
}

/* ---- hypot ------------------------------------------------------------------------------- */

/* sqrt(x² + y²) without overflow or underflow in between: the larger magnitude is scaled by a
 * power of two (exact) into [2^-59, 2^58] first, and the sum of squares is one fma. */
inline float exact_hypot(float x, float y) {
    float ax = fabs(x), ay = fabs(y);
    float hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
    float scale = hi > 0x1p50f ? 0x1p-70f : hi < 0x1p-50f ? 0x1p90f : 1.0f;
    float unscale = hi > 0x1p50f ? 0x1p70f : hi < 0x1p-50f ? 0x1p-90f : 1.0f;
    hi *= scale;
    lo *= scale;
    return sqrt(fma(hi, hi, lo * lo)) * unscale;
}

/* ---- Vectors ----------------------------------------------------------------------------- */

/* (a.x·b.x + a.y·b.y) + a.z·b.z, every product and sum rounded, in this order. */
inline float exact_dot3(float3 a, float3 b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }

/* sqrt(exact_dot3(v, v)): unscaled, so components beyond ~1.8e19 overflow. */
inline float exact_length3(float3 v) { return sqrt(exact_dot3(v, v)); }

/* v · (1 / |v|): one division and three products (rather than three divisions). */
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
