/* The independent sampler (-D SAMPLER_INDEPENDENT): every number its own hash.
 * Included by rng.cl after the hashes and SampleStream it uses; defines sampler_1d and
 * sampler_2d, the numbers of dimension dim (and dim + 1) of the stream's sample. */
#ifndef MCRT_SAMPLER_INDEPENDENT_CL
#define MCRT_SAMPLER_INDEPENDENT_CL

inline float sampler_1d(const SampleStream* s, uint dim) {
    return independent_1d(s->pixel, s->index, dim, s->seed);
}

/* Dimensions dim and dim + 1, from one hash. */
inline float2 sampler_2d(const SampleStream* s, uint dim) {
    return independent_2d(s->pixel, s->index, dim, s->seed);
}

#endif
