/* Counter-based random numbers: u_d = pcg4d(pixel, sample, d, seed).x / 2^32, a pure function
 * of (seed, pixel, sample index, dimension) with no state carried between launches, so the
 * image does not depend on batching or device split (DESIGN.md "Determinism"). */
#ifndef MCRT_RNG_CL
#define MCRT_RNG_CL

/* Jarzynski & Olano 2020, "Hash Functions for GPU Rendering" (JCGT 9(3)), pcg4d. */
inline uint4 pcg4d(uint4 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

/* The 24 high bits as a float in [0, 1): exact, and never 1. */
inline float uint_to_unit_float(uint x) { return (float)(x >> 8) * 0x1.0p-24f; }

/* Identifies one pixel sample's stream of random numbers. */
typedef struct {
    uint pixel;
    uint sample;
    uint seed;
} SampleStream;

/* Dimensions of the stream, shared by every estimator so that two estimators can be compared
 * on the same samples. */
#define DIM_PIXEL_JITTER 0u /* 2D */
#define DIM_LIGHT_SELECT 2u /* 1D */
#define DIM_LIGHT_POINT 3u  /* 2D */

inline float sample_1d(const SampleStream* s, uint dim) {
    return uint_to_unit_float(pcg4d((uint4)(s->pixel, s->sample, dim, s->seed)).x);
}

/* Dimensions dim and dim + 1. */
inline float2 sample_2d(const SampleStream* s, uint dim) {
    return (float2)(sample_1d(s, dim), sample_1d(s, dim + 1u));
}

#endif
