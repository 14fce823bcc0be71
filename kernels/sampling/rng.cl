/* Counter-based sample generators: every number is a pure function of (seed, pixel, sample
 * index, dimension), with no state carried between launches, so the image does not depend on
 * batching or device split (DESIGN.md "Determinism"). The sampler is chosen at compile time:
 * -D SAMPLER_INDEPENDENT, SAMPLER_STRATIFIED or SAMPLER_SOBOL, one file each below. */
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

/* Identifies one pixel sample's stream of random numbers. A pixel's spp samples are split into
 * `replicates` independent randomizations of the sampler (independent Owen scrambles, strata
 * permutations, spiral rotations: L'Ecuyer & Lemieux 2002; Owen 1997), so that the spread of the
 * replicate means is an honest error bar for correlated samples; `sample` and `sample_count`
 * are within the replicate. */
typedef struct {
    uint pixel;
    uint sample;       /* index of the sample within its replicate */
    uint sample_count; /* samples per pixel per replicate (strata, spiral points, Sobol prefix) */
    uint seed;
    uint replicate;    /* which randomization, 0 .. replicates − 1 */
    uint index;        /* index of the sample within the pixel: replicate + replicates · sample */
    uint vertex;       /* the path's vertex the numbers are for: 0 at the camera's hit, k after
                          k reflections (stream_dimension) */
} SampleStream;

/* The seed of this replicate's randomization: the render's seed for replicate 0. */
inline uint replicate_seed(const SampleStream* s) { return s->seed ^ (s->replicate * 0x9E3779B9u); }

/* Dimensions of the stream, shared by every estimator (a user's too) so that two estimators
 * are compared on the same samples (common random numbers). A 2D dimension d uses d and d + 1.
 * They are the dimensions of one path vertex: vertex k of a path (k reflections after the
 * camera's hit) reads dimension d as stream_dimension() maps it, so that each vertex has its
 * own numbers and an estimator is written once for every vertex. */
/* DIM_ROULETTE, at vertices k >= 1 only (the jitter's slot): Russian roulette before the path
 * reaches vertex k (path.cl). The path goes on by bsdf_sample of DIM_DIRECTION's numbers. */
#define DIM_PIXEL_JITTER 0u   /* 2D, vertex 0 only: the point in the pixel */
#define DIM_ROULETTE 0u       /* 1D, vertices k >= 1 */
#define DIM_LIGHT_FINE 2u     /* 1D: refines DIM_LIGHT's x below the light selection's grid */
#define DIM_LIGHT 3u          /* 2D: x chooses the light and, remapped, with y the point on it
                                 (or the direction in its spherical triangle): one stratified
                                 sample for both (discrete.cl) */
#define DIM_DIRECTION 5u      /* 2D: hemisphere or BSDF direction (hemisphere, MIS, ambient) */
#define DIM_PIXEL_ROTATION 7u /* 2D, per pixel: rotation of the Fibonacci spiral */
/* 1D, textured builds: the key of a vertex's stochastic transparency (path.cl, textures.cl);
 * beyond the vertices' blocks, so that untextured renders read exactly the numbers they did. */
#define DIM_ALPHA 0x80000u
/* Dimensions DIM_USER, DIM_USER + 1, ... belong to users' estimators: no built-in code uses
 * them, now or later (docs/ESTIMATORS.md); DIM_USER_PER_VERTEX of them at each vertex. */
#define DIM_USER 0x100000u
#define DIM_USER_PER_VERTEX 0x100u
/* Built-in dimensions per vertex: vertex k uses DIM_PER_VERTEX·k + d. */
#define DIM_PER_VERTEX 8u
/* The stratified and Sobol' samplers cover the first MCRT_QMC_VERTICES vertices of a path; past
 * them every number is independent (pcg4d), so a deep path never runs out of dimensions and pays
 * for no strata where the integrand is too high-dimensional for them to help (PBRT 3rd ed. 7.2.3
 * on padding; the independent sampler is the same everywhere). */
#define MCRT_QMC_VERTICES 16u
/* The stream's dimension for estimator dimension dim at the stream's vertex: dim itself at
 * vertex 0 (so that direct lighting reads exactly the numbers it always did). */
inline uint stream_dimension(const SampleStream* s, uint dim) {
    if (dim >= DIM_USER) return dim + s->vertex * DIM_USER_PER_VERTEX;
    return dim + s->vertex * DIM_PER_VERTEX;
}

/* True for a mapped dimension past the stratified / Sobol' vertices: independent numbers. */
inline bool past_qmc_vertices(const SampleStream* s) { return s->vertex >= MCRT_QMC_VERTICES; }

/* Independent uniform number of dimension dim: pcg4d(pixel, sample, dim, seed).x. */
inline float independent_1d(uint pixel, uint sample, uint dim, uint seed) {
    return uint_to_unit_float(pcg4d((uint4)(pixel, sample, dim, seed)).x);
}

/* Two independent uniform numbers for the pair (dim, dim + 1): the first two of the four words of
 * one pcg4d(pixel, sample, dim, seed), whose outputs are independent of each other (Jarzynski &
 * Olano 2020 test all four): one hash for a 2D sample instead of two. The first is
 * independent_1d of dim; the second is not that of dim + 1, and nothing reads both. */
inline float2 independent_2d(uint pixel, uint sample, uint dim, uint seed) {
    uint4 h = pcg4d((uint4)(pixel, sample, dim, seed));
    return (float2)(uint_to_unit_float(h.x), uint_to_unit_float(h.y));
}

/* A hash key for one (pixel, dimension), the same for all samples of the pixel. */
inline uint pixel_dimension_key(const SampleStream* s, uint dim) {
    return pcg4d((uint4)(s->pixel, 0xffffffffu, dim, replicate_seed(s))).y;
}

/* Numbers that depend on the pixel only, not on the sample (e.g. a per-pixel rotation). */
inline float2 pixel_2d(const SampleStream* s, uint dim) {
    dim = stream_dimension(s, dim);
    uint4 h = pcg4d((uint4)(s->pixel, 0xfffffffeu, dim, replicate_seed(s)));
    return (float2)(uint_to_unit_float(h.x), uint_to_unit_float(h.y));
}

/* The sampler the render was built for, one file each in kernels/sampling/ (the host's table of
 * variants, host/render/variants.cpp): each defines sampler_1d and sampler_2d. */
#if defined(SAMPLER_STRATIFIED)
#include "sampler_stratified.cl"
#elif defined(SAMPLER_SOBOL)
#include "sampler_sobol.cl"
#elif defined(SAMPLER_INDEPENDENT)
#include "sampler_independent.cl"
#else
#error "no sampler: the host defines one SAMPLER_* (host/render/variants.cpp)"
#endif

/* ---- What estimators call ------------------------------------------------------------------- */

/* The number of dimension dim (or the pair dim, dim + 1) at the stream's vertex. */
inline float sample_1d(const SampleStream* s, uint dim) {
    uint d = stream_dimension(s, dim);
    if (past_qmc_vertices(s)) return independent_1d(s->pixel, s->index, d, s->seed);
    return sampler_1d(s, d);
}

inline float2 sample_2d(const SampleStream* s, uint dim) {
    uint d = stream_dimension(s, dim);
    if (past_qmc_vertices(s)) return independent_2d(s->pixel, s->index, d, s->seed);
    return sampler_2d(s, d);
}

#endif
