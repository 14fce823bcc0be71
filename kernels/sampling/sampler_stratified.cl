/* The stratified sampler (-D SAMPLER_STRATIFIED): jittered strata in a hashed order.
 * Included by rng.cl after the hashes and SampleStream it uses; defines sampler_1d and
 * sampler_2d, the numbers of dimension dim (and dim + 1) of the stream's sample. */
#ifndef MCRT_SAMPLER_STRATIFIED_CL
#define MCRT_SAMPLER_STRATIFIED_CL

/* Kensler 2013, "Correlated Multi-Jittered Sampling" (Pixar TM 13-01), permute(): a hashed
 * permutation of [0, l) by cycle walking; p selects the permutation. */
inline uint kensler_permute(uint i, uint l, uint p) {
    uint w = l - 1u;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    do {
        i ^= p;
        i *= 0xe170893du;
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i *= 0x0929eb3fu;
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i *= 1u | p >> 27;
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5;
    } while (i >= l);
    return (i + p) % l;
}

/* Jittered strata: sample k of the pixel falls in stratum permute(k) of sample_count strata
 * (1D) or of an nx × ny grid (2D, per dimension pair), each pair with its own permutation so
 * that pairs are not correlated; uniform jitter inside the stratum (PBRT 3rd ed. 7.3). */
inline float sampler_1d(const SampleStream* s, uint dim) {
    uint stratum = kensler_permute(s->sample, s->sample_count, pixel_dimension_key(s, dim));
    float jitter = independent_1d(s->pixel, s->index, dim, s->seed);
    return min(((float)stratum + jitter) / (float)s->sample_count, 0x1.fffffep-1f);
}

inline float2 sampler_2d(const SampleStream* s, uint dim) {
    uint nx = (uint)ceil(sqrt((float)s->sample_count));
    while (nx * nx < s->sample_count) ++nx; /* float sqrt may round down */
    uint ny = (s->sample_count + nx - 1u) / nx;
    uint stratum = kensler_permute(s->sample, nx * ny, pixel_dimension_key(s, dim));
    float2 jitter = independent_2d(s->pixel, s->index, dim, s->seed);
    float2 v = (float2)(((float)(stratum % nx) + jitter.x) / (float)nx,
                        ((float)(stratum / nx) + jitter.y) / (float)ny);
    return min(v, (float2)(0x1.fffffep-1f));
}

#endif
