/* Warps from [0,1)^n to sampled domains, each with its pdf twin named by measure and taking
 * exactly what the routine returns, and its inverse where one exists. Directions are in the
 * local frame, z up (frame.cl). Samplers never draw their own random numbers. */
#ifndef MCRT_SAMPLING_CL
#define MCRT_SAMPLING_CL

#include "shared_types.h"

#define INV_2PI_F 0.159154943091895336f

/* v / |v|, or fallback when v is zero or not finite. */
inline float3 normalize_or(float3 v, float3 fallback) {
    float l2 = dot(v, v);
    return (l2 > 0.0f && isfinite(l2)) ? normalize(v) : fallback;
}

/* atan2(y, x) / 2π in [0, 1). */
inline float azimuth_fraction(float y, float x) {
    float f = atan2(y, x) * INV_2PI_F;
    f = f < 0.0f ? f + 1.0f : f;
    return f < 1.0f ? f : 0.0f;
}

/* The largest float below 1: inverses clamp to [0, ONE_MINUS_EPSILON] so they return a valid u. */
#define ONE_MINUS_EPSILON_F 0x1.fffffep-1f

inline float2 clamp_unit(float2 u) {
    return clamp(u, (float2)(0.0f), (float2)(ONE_MINUS_EPSILON_F));
}

/* ---- Triangles ------------------------------------------------------------------------- */

/* Uniform point on a triangle, returned as barycentrics (b1, b2) of p1, p2: b0 = 1 − √u0,
 * b1 = u1·√u0 (Osada et al. 2002; PBRT 3rd ed. 13.6.5). */
inline float2 sample_triangle_uniform(float2 u) {
    float su0 = sqrt(u.x);
    float b0 = 1.0f - su0;
    float b1 = u.y * su0;
    return (float2)(b1, 1.0f - b0 - b1);
}

/* Density of sample_triangle_uniform with respect to area on a triangle of the given area. */
inline float sample_triangle_uniform_pdf_a(float area) { return 1.0f / area; }

/* u of sample_triangle_uniform from barycentrics (b1, b2): b1 + b2 = √u0, b1 = u1·√u0. */
inline float2 invert_triangle_uniform(float2 b) {
    float s = b.x + b.y;
    return clamp_unit((float2)(s * s, s > 0.0f ? b.x / s : 0.5f));
}

/* ---- Hemisphere ------------------------------------------------------------------------ */

/* Uniform direction on the hemisphere z > 0 (GI Compendium eq. 34): z = 1 − u0 lies in (0, 1],
 * so a sample never has zero density. */
inline float3 sample_hemisphere_uniform(float2 u) {
    float z = 1.0f - u.x;
    float r = sqrt(max(0.0f, u.x * (2.0f - u.x))); /* √(1 − z²) without cancellation */
    float turns = 2.0f * u.y; /* φ/π, exact */
    return (float3)(r * cospi(turns), r * sinpi(turns), z);
}

/* Density of sample_hemisphere_uniform with respect to solid angle: 1/(2π) above the horizon. */
inline float sample_hemisphere_uniform_pdf_w(float3 w) { return w.z > 0.0f ? INV_2PI_F : 0.0f; }

inline float2 invert_hemisphere_uniform(float3 w) {
    return clamp_unit((float2)(1.0f - w.z, azimuth_fraction(w.y, w.x)));
}

/* Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square": [0,1)² to the unit disk,
 * concentric squares to concentric circles, so strata stay compact. */
inline float2 sample_disk_concentric(float2 u) {
    float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    if (a == 0.0f && b == 0.0f) return (float2)(0.0f, 0.0f);
    float r, turns; /* φ/π */
    if (fabs(a) > fabs(b)) {
        r = a;
        turns = 0.25f * (b / a);
    } else {
        r = b;
        turns = 0.5f - 0.25f * (a / b);
    }
    return (float2)(r * cospi(turns), r * sinpi(turns));
}

/* Inverse of sample_disk_concentric: the square's sector from the polar angle. */
inline float2 invert_disk_concentric(float2 p) {
    float r = hypot(p.x, p.y);
    float phi = atan2(p.y, p.x);                     /* (−π, π] */
    if (phi < -0.25f * M_PI_F) phi += 2.0f * M_PI_F; /* [−π/4, 7π/4) */
    float k = 4.0f * MCRT_INV_PI, a, b;
    if (phi < 0.25f * M_PI_F) { /* right sector: r = a */
        a = r;
        b = r * phi * k;
    } else if (phi < 0.75f * M_PI_F) { /* top: r = b */
        b = r;
        a = r * (0.5f * M_PI_F - phi) * k;
    } else if (phi < 1.25f * M_PI_F) { /* left: r = a < 0 */
        a = -r;
        b = -r * (phi - M_PI_F) * k;
    } else { /* bottom: r = b < 0 */
        b = -r;
        a = -r * (1.5f * M_PI_F - phi) * k;
    }
    return clamp_unit((float2)(0.5f * (a + 1.0f), 0.5f * (b + 1.0f)));
}

/* Cosine-weighted direction on the hemisphere (GI Compendium eq. 35), by Malley's method: a
 * uniform point of the unit disk (concentric map) lifted to the hemisphere. The disk radius is
 * max(|2u0 − 1|, |2u1 − 1|), so z = √((1 − r)(1 + r)) is accurate near the horizon; z is kept at
 * least 2^-23 (a change of measure 2^-46), so a sample never has zero density. */
inline float3 sample_hemisphere_cosine(float2 u) {
    float2 d = sample_disk_concentric(u);
    float r = max(fabs(2.0f * u.x - 1.0f), fabs(2.0f * u.y - 1.0f));
    float z = sqrt(max((1.0f - r) * (1.0f + r), 0x1.0p-46f));
    return (float3)(d.x, d.y, z);
}

/* Density of sample_hemisphere_cosine with respect to solid angle: cosθ/π above the horizon. */
inline float sample_hemisphere_cosine_pdf_w(float3 w) { return w.z > 0.0f ? w.z * MCRT_INV_PI : 0.0f; }

inline float2 invert_hemisphere_cosine(float3 w) { return invert_disk_concentric(w.xy); }

/* ---- Spherical triangles (Arvo 1995, "Stratified Sampling of Spherical Triangles") ------- */

/* Solid angle of the spherical triangle of unit vectors a, b, c (Van Oosterom & Strackee 1983):
 * tan(Ω/2) = |a·(b×c)| / (1 + a·b + b·c + c·a). The triple product is taken as a·((b−a)×(c−a)),
 * equal in exact arithmetic and free of cancellation when the triangle is small. */
inline float spherical_triangle_solid_angle(float3 a, float3 b, float3 c) {
    float triple = fabs(dot(a, cross(b - a, c - a)));
    float denom = 1.0f + dot(a, b) + dot(b, c) + dot(c, a);
    return 2.0f * atan2(triple, denom);
}

/* Direction uniform in solid angle over the spherical triangle of unit vectors a, b, c, unit;
 * the _omega form takes the triangle's solid angle, when the caller already has it.
 * Arvo's two steps, with the first solved in closed form from Van Oosterom's formula instead of
 * the vertex angles (whose sum minus π cancels catastrophically for small triangles):
 * 1. c' = cos θ·a + sin θ·c⊥ on the arc a→c such that Ω(a, b, c') = u0·Ω. With t = tan(θ/2),
 *    T = a·(b×c⊥), tan(Ω'/2) = t|T| / (1 + a·b + t·b·c⊥), which is linear in t once Ω' is set.
 * 2. w on the arc b→c' with 1 − w·b uniform in [0, 1 − c'·b] (uniform over the thin wedge).
 * χ²-tested from 4 sr down to 1e-3 sr; inside the triangle and invertible down to 1e-7 sr and
 * slivers, but callers sample lights below ~3e-4 sr by area instead, as pbrt-v4 does. Never
 * NaN: a degenerate triangle (Ω = 0) gives the normalized vertex average. */
inline float3 sample_spherical_triangle_omega(float3 a, float3 b, float3 c, float omega,
                                              float2 u) {
    float3 fallback = normalize_or(a + b + c, a);
    if (!(omega > 0.0f) || !isfinite(omega)) return fallback;

    /* Step 1: c' splits off the sub-triangle (a, b, c') of solid angle u0·Ω. Differences to a
     * keep every quantity accurate relative to the triangle's size. */
    float3 ac = c - a, ba = b - a;
    float3 c_perp = normalize_or(ac - dot(ac, a) * a, fallback); /* tangent of arc a→c at a */
    float T = fabs(dot(ba, cross(c_perp, a)));                   /* a·(b×c⊥) */
    float b_dot_c_perp = dot(ba, c_perp);                        /* b·c⊥, as a·c⊥ = 0 */
    float one_plus_ab = 2.0f - 0.5f * dot(ba, ba);               /* 1 + a·b */
    /* sin and cos of u0·Ω/2 in [0, π) as sinpi/cospi of its fraction of π: no general argument
     * reduction (PoCL's was a quarter of this estimator's time with atan2). */
    float turns = u.x * omega * (0.5f * M_1_PI_F);
    float sh = sinpi(turns), ch = cospi(turns);
    /* θ/2 = atan2(y, x), but only cos θ and sin θ are needed: the double-angle formulas of the
     * vector (x, y). θ is at most the arc a→c, whose half is atan2(|c − a|, |c + a|); compared
     * by the sign of a 2D cross product, both half-angles being in [0, π]. */
    float y = sh * one_plus_ab, x = T * ch - sh * b_dot_c_perp;
    float3 cp;
    if (y * length(c + a) >= x * length(ac)) {
        cp = c; /* at or beyond the end of the arc (rounding): c' = c */
    } else {
        float r2 = x * x + y * y;
        cp = (r2 > 0.0f) ? ((x * x - y * y) * a + (2.0f * x * y) * c_perp) / r2 : a;
    }

    /* Step 2: along the arc b→c', uniform in 1 − cos of the arc length from b. */
    float3 bc = cp - b;
    float one_minus_z = u.y * clamp(0.5f * dot(bc, bc), 0.0f, 2.0f); /* u1·(1 − c'·b) */
    float sin_arc = sqrt(max(0.0f, one_minus_z * (2.0f - one_minus_z)));
    float3 bc_perp = normalize_or(bc - dot(bc, b) * b, fallback); /* tangent of arc b→c' at b */
    float3 w = normalize_or((1.0f - one_minus_z) * b + sin_arc * bc_perp, fallback);
    return (isfinite(w.x) && isfinite(w.y) && isfinite(w.z)) ? w : fallback;
}

inline float3 sample_spherical_triangle(float3 a, float3 b, float3 c, float2 u) {
    return sample_spherical_triangle_omega(a, b, c, spherical_triangle_solid_angle(a, b, c), u);
}

/* Density of sample_spherical_triangle with respect to solid angle: 1/Ω when w is inside the
 * triangle (on the inner side of its three great circles), else 0. */
inline float sample_spherical_triangle_pdf_w(float3 a, float3 b, float3 c, float3 w) {
    float omega = spherical_triangle_solid_angle(a, b, c);
    if (!(omega > 0.0f)) return 0.0f;
    /* The side of each great circle (p, q) as (w − p)·(p × (q − p)), equal to w·(p × q) but
     * accurate relative to the triangle's size. */
    float s = dot(a, cross(b - a, c - a)) >= 0.0f ? 1.0f : -1.0f; /* orientation */
    if (s * dot(w - a, cross(a, b - a)) < 0.0f || s * dot(w - b, cross(b, c - b)) < 0.0f ||
        s * dot(w - c, cross(c, a - c)) < 0.0f)
        return 0.0f;
    return 1.0f / omega;
}

/* u of sample_spherical_triangle from a direction w inside the triangle (after pbrt-v4's
 * InvertSphericalTriangleSample, derived anew): c' is where the great circle through b and w
 * meets the arc a→c, u0 = Ω(a, b, c')/Ω and u1 = (1 − w·b)/(1 − c'·b). Singular at w = b. */
inline float2 invert_spherical_triangle(float3 a, float3 b, float3 c, float3 w) {
    float omega = spherical_triangle_solid_angle(a, b, c);
    if (!(omega > 0.0f)) return (float2)(0.5f, 0.5f);
    float3 n_bw = cross(b, w - b), n_ac = cross(a, c - a);
    float3 cp = normalize_or(cross(n_bw, n_ac), c);
    if (dot(cp, a + c) < 0.0f) cp = -cp;
    float u0 = spherical_triangle_solid_angle(a, b, cp) / omega;
    float3 bw = w - b, bc = cp - b;
    float denom = dot(bc, bc);
    float u1 = denom > 0.0f ? dot(bw, bw) / denom : 0.0f;
    return clamp_unit((float2)(u0, u1));
}

/* ---- Spherical Fibonacci on the hemisphere --------------------------------------------- */

/* Point i of n of a spherical Fibonacci spiral on the hemisphere (Keinert et al. 2015,
 * "Spherical Fibonacci Mapping"; Marques et al. 2013), perturbed by u shared by the n points:
 * z = 1 − (i + u0)/n puts point i uniformly in the i-th z-band of solid angle 2π/n, and
 * φ = 2π·frac(i·(Φ−1) + u1) rotates the spiral. Over uniform u, a point picked at random from
 * the set is uniform on the hemisphere, so (2π/n)·Σ f(w_i) estimates ∫f without bias.
 * i·(Φ−1) mod 1 is computed in 32-bit fixed point from the 64-bit constant
 * (Φ−1)·2^64 = 0x9E3779B97F4A7C15, exact to 2^-32 + i·2^-64 for every uint i. */
inline float3 sample_hemisphere_fibonacci(uint i, uint n, float2 u) {
    uint golden = i * 0x9E3779B9u + mul_hi(i, 0x7F4A7C15u);
    uint offset = (uint)(min(u.y, ONE_MINUS_EPSILON_F) * 4294967296.0f);
    float turns = 2.0f * ((float)((golden + offset) >> 8) * 0x1.0p-24f); /* φ/π */
    float inv_n = 1.0f / (float)n;
    float one_minus_z = ((float)i + u.x) * inv_n; /* accurate near the pole */
    float z = ((float)(n - i) - u.x) * inv_n;     /* accurate near the horizon, > 0 */
    float r = sqrt(max(0.0f, one_minus_z * (1.0f + z)));
    return (float3)(r * cospi(turns), r * sinpi(turns), z);
}

/* Density of sample_hemisphere_fibonacci with respect to solid angle, marginally over the point
 * index (each point i alone is uniform on its band, density n/(2π) there): 1/(2π) above the
 * horizon, the density an estimator (1/n)·Σ f/pdf_w divides by. */
inline float sample_hemisphere_fibonacci_pdf_w(float3 w) { return w.z > 0.0f ? INV_2PI_F : 0.0f; }

#endif
