/* The Sobol' sampler (-D SAMPLER_SOBOL): Owen-scrambled (0,2)-sequences per dimension pair.
 * Included by rng.cl after the hashes and SampleStream it uses; defines sampler_1d and
 * sampler_2d, the numbers of dimension dim (and dim + 1) of the stream's sample. */
#ifndef MCRT_SAMPLER_SOBOL_CL
#define MCRT_SAMPLER_SOBOL_CL

inline uint reverse_bits(uint x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* Burley 2020, "Practical Hash-based Owen Scrambling" (JCGT 9(4)): the Laine–Karras style hash
 * applied to the bit-reversed value is a nested uniform (Owen) scramble. */
inline uint laine_karras_permutation(uint x, uint seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

inline uint nested_uniform_scramble(uint x, uint seed) {
    return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

/* The first two Sobol' dimensions: van der Corput, and the one with direction numbers
 * v_1 = 2^31, v_k = v_{k-1} ^ (v_{k-1} >> 1) (primitive polynomial x + 1), here bit-reversed
 * (v_1 = 1, v_k = v_{k-1} ^ (v_{k-1} << 1)): what the scramble below reverses first. */
inline uint sobol_dimension_1_reversed(uint index) {
    uint x = 0u, v = 1u;
    for (; index != 0u; index >>= 1, v ^= v << 1)
        if (index & 1u) x ^= v;
    return x;
}

/* The three seeds of a pair's scrambles, per (pixel, dimension, replicate): y shuffles the sample
 * index (as pixel_dimension_key), z and w scramble the two coordinates; three words of one hash,
 * not three hashes. */
inline uint4 sobol_keys(const SampleStream* s, uint dim) {
    return pcg4d((uint4)(s->pixel, 0xffffffffu, dim, replicate_seed(s)));
}

/* Owen-scrambled Sobol' (0,2)-sequence per dimension pair, padded by shuffling the sample index
 * with an independent scramble for each pair (Burley 2020, sec. 4). The coordinates are
 * nested_uniform_scramble(reverse_bits(index)) and nested_uniform_scramble(sobol_dimension_1(
 * index)), written without the bit reversals that cancel (reverse_bits is an involution): 3
 * reversals per pair instead of 6, the same bits. */
inline float2 sampler_2d(const SampleStream* s, uint dim) {
    uint4 key = sobol_keys(s, dim);
    uint index = nested_uniform_scramble(s->sample, key.y);
    uint x = reverse_bits(laine_karras_permutation(index, key.z));
    uint y = reverse_bits(laine_karras_permutation(sobol_dimension_1_reversed(index), key.w));
    return (float2)(uint_to_unit_float(x), uint_to_unit_float(y));
}

inline float sampler_1d(const SampleStream* s, uint dim) {
    uint4 key = sobol_keys(s, dim);
    uint index = nested_uniform_scramble(s->sample, key.y);
    return uint_to_unit_float(reverse_bits(laine_karras_permutation(index, key.z)));
}

#endif
