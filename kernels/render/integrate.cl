/* `mcrt integrate`: estimators of ∫_Ω cosθ dω = π over the hemisphere (z up), one work-item
 * per sample. Each work-item writes its sample's f(w)/pdf_w(w); the host sums them per repeat
 * in double, in sample order, so the output depends only on (seed, n, repeats).
 *
 * Work-item k ∈ [first, first + global size) is sample i = k mod n of repeat r = k / n; the
 * launch covers samples of several repeats or a part of one, as the host chunks them. */
#include "rng.cl"
#include "sampling.cl"

/* Dimensions of the hash's input (repeat, sample, dimension, seed): the direction of one
 * independent sample, and the per-repeat rotation and offset of the Fibonacci spiral. */
#define INTEGRATE_DIM_DIRECTION 0u /* 2D */
#define INTEGRATE_DIM_SPIRAL 1u    /* 2D, at sample INTEGRATE_REPEAT_SAMPLE */
#define INTEGRATE_REPEAT_SAMPLE 0xffffffffu

/* Two independent uniform numbers in [0, 1), a pure function of (repeat, sample, dim, seed). */
inline float2 integrate_2d(uint repeat, uint sample, uint dim, uint seed) {
    uint4 h = pcg4d((uint4)(repeat, sample, dim, seed));
    return (float2)(uint_to_unit_float(h.x), uint_to_unit_float(h.y));
}

/* The integrand: f(w) = cosθ = w.z. */
inline float cos_integrand(float3 w) { return w.z; }

/* f/pdf, or 0 where the pdf vanishes (f vanishes there too for a pdf that covers the support). */
inline float f_over_pdf(float3 w, float pdf_w) {
    return pdf_w > 0.0f ? cos_integrand(w) / pdf_w : 0.0f;
}

/* Uniform hemisphere directions, pdf 1/(2π) (GI Compendium eq. 34).
 * Reads nothing; writes out[k − first] = f/pdf of sample (r, i). */
__kernel void integrate_uniform(ulong first, uint n, uint seed, __global float* out) {
    ulong k = first + get_global_id(0);
    float2 u = integrate_2d((uint)(k / n), (uint)(k % n), INTEGRATE_DIM_DIRECTION, seed);
    float3 w = sample_hemisphere_uniform(u);
    out[get_global_id(0)] = f_over_pdf(w, sample_hemisphere_uniform_pdf_w(w));
}

/* Cosine-weighted directions, pdf cosθ/π (GI Compendium eq. 35): f/pdf = π for every sample.
 * Reads nothing; writes out[k − first] = f/pdf of sample (r, i). */
__kernel void integrate_cosine(ulong first, uint n, uint seed, __global float* out) {
    ulong k = first + get_global_id(0);
    float2 u = integrate_2d((uint)(k / n), (uint)(k % n), INTEGRATE_DIM_DIRECTION, seed);
    float3 w = sample_hemisphere_cosine(u);
    out[get_global_id(0)] = f_over_pdf(w, sample_hemisphere_cosine_pdf_w(w));
}

/* Point i of the n-point spherical Fibonacci spiral, rotated and offset by u, which depends on
 * (seed, repeat) only; with the marginal pdf 1/(2π) the mean is (2π/n) Σ cosθ_i.
 * Reads nothing; writes out[k − first] = f/pdf of sample (r, i). */
__kernel void integrate_fibonacci(ulong first, uint n, uint seed, __global float* out) {
    ulong k = first + get_global_id(0);
    float2 u = integrate_2d((uint)(k / n), INTEGRATE_REPEAT_SAMPLE, INTEGRATE_DIM_SPIRAL, seed);
    float3 w = sample_hemisphere_fibonacci((uint)(k % n), n, u);
    out[get_global_id(0)] = f_over_pdf(w, sample_hemisphere_fibonacci_pdf_w(w));
}
