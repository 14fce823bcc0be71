/* Sampling an index from a discrete distribution built on the host (host/render/discrete.h):
 * by CDF inversion or with an alias table. Each sampler reports the pmf of what it returns. */
#ifndef MCRT_DISCRETE_CL
#define MCRT_DISCRETE_CL

#include "shared_types.h"

typedef struct {
    uint index;
    float pmf;     /* probability of index, as the distribution's *_pmf function gives it */
    float u_remap; /* where u fell within the preimage of index, rescaled to [0, 1): uniform and
                      independent of the choice, so the same sample serves what comes next */
} DiscreteSample;

/* Every sampler below reads u on the 2^-24 grid, k = ⌊u·2^24⌋ (exactly u for the independent
 * and Sobol samplers), and refines it with u_fine ∈ [0, 1) from another dimension: the
 * continuous number (k + u_fine)·2^-24 is uniform on [0, 1), the choice depends on k alone, and
 * u_remap is the position of k + u_fine within the run of k values that give the choice —
 * exactly uniform on [0, 1), at full float precision even for a choice of one grid step. This is
 * how a light's triangle and the point on it come from one (stratified) sample (Mitsuba 3 and
 * pbrt-v4 reuse the selection sample the same way). */

/* (k − first + u_fine) / count, kept below 1 under rounding. */
inline float remap_run(uint k, uint first, uint count, float u_fine) {
    float r = ((float)(k - first) + u_fine) / (float)count;
    return min(r, 0x1.fffffep-1f);
}

inline uint unit_to_grid(float u) { return min((uint)(u * 16777216.0f), 16777215u); }

/* Uniform choice of one of n > 0: pmf 1/n. */
inline DiscreteSample sample_discrete_uniform(uint n, float u, float u_fine) {
    DiscreteSample s;
    s.index = min((uint)(u * (float)n), n - 1u);
    s.pmf = 1.0f / (float)n;
    /* u·n − index in one rounding, refined by u_fine over one grid step (n·2^-24 here). */
    float r = fma(u, (float)n, -(float)s.index) + u_fine * ((float)n * 0x1.0p-24f);
    s.u_remap = clamp(r, 0.0f, 0x1.fffffep-1f);
    return s;
}

/* CDF inversion by binary search (PBRT 3rd ed. 13.3.1): cdf has n + 1 entries, cdf[0] = 0,
 * cdf[n] = 1, n > 0, and u is in [0, 1). Returns the last i with cdf[i] <= u; its interval
 * [cdf[i], cdf[i+1]) contains u, so an empty interval (zero pmf) is never returned. */
inline DiscreteSample sample_discrete_cdf(global const float* cdf, uint n, float u, float u_fine) {
    uint lo = 0u, hi = n; /* invariant: cdf[lo] <= u < cdf[hi] */
    while (hi - lo > 1u) {
        uint mid = lo + (hi - lo) / 2u;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    DiscreteSample s;
    s.index = lo;
    s.pmf = cdf[lo + 1u] - cdf[lo];
    /* The interval is [cdf[lo], cdf[lo + 1]), whole grid steps (host/render/discrete.h). */
    uint first = (uint)(cdf[lo] * 16777216.0f), last = (uint)(cdf[lo + 1u] * 16777216.0f);
    uint k = clamp(unit_to_grid(u), first, last - 1u);
    s.u_remap = remap_run(k, first, last - first, u_fine);
    return s;
}

/* Probability that sample_discrete_cdf returns i < n. */
inline float discrete_cdf_pmf(global const float* cdf, uint i) { return cdf[i + 1u] - cdf[i]; }

/* Alias method (Walker 1977; Vose 1991) with one number on the 2^-24 grid: k = u·2^24 and
 * k·n (exact in 64 bits) give the bucket, k·n / 2^24, and the coin, k·n mod 2^24, both integers,
 * so the probability of each outcome is a count of k values that the host's build_alias_table
 * makes the reported pmf. n > 0 and u in [0, 1). Entries of zero pmf (zero weight) have
 * threshold 0 and are never an alias. */
inline DiscreteSample sample_discrete_alias(global const AliasEntry* table, uint n, float u,
                                            float u_fine) {
    uint k = unit_to_grid(u);
    ulong t = (ulong)k * (ulong)n;
    uint bucket = (uint)(t >> 24);
    uint coin = (uint)(t & 0xfffffful);
    AliasEntry e = table[bucket];
    DiscreteSample s;
    bool keeps = coin < e.threshold;
    s.index = keeps ? bucket : e.alias;
    s.pmf = table[s.index].pmf;
    /* The k of this bucket are [k0, k2), those below the threshold [k0, k1): k·n falls in
     * [bucket·2^24, bucket·2^24 + threshold) for k < k1 = ⌈(bucket·2^24 + threshold)/n⌉. */
    ulong base = (ulong)bucket << 24;
    uint k0 = (uint)((base + n - 1ul) / n);
    uint k1 = (uint)((base + e.threshold + n - 1ul) / n);
    uint k2 = (uint)((base + 16777216ul + n - 1ul) / n);
    s.u_remap = keeps ? remap_run(k, k0, k1 - k0, u_fine) : remap_run(k, k1, k2 - k1, u_fine);
    return s;
}

/* Probability that sample_discrete_alias returns i < n. */
inline float discrete_alias_pmf(global const AliasEntry* t, uint i) { return t[i].pmf; }

#endif
