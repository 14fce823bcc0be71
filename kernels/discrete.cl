/* Sampling an index from a discrete distribution built on the host (host/render/discrete.h):
 * by CDF inversion or with an alias table. Each sampler reports the pmf of what it returns. */
#ifndef MCRT_DISCRETE_CL
#define MCRT_DISCRETE_CL

#include "shared_types.h"

typedef struct {
    uint index;
    float pmf; /* probability of index, as the distribution's *_pmf function gives it */
} DiscreteSample;

/* CDF inversion by binary search (PBRT 3rd ed. 13.3.1): cdf has n + 1 entries, cdf[0] = 0,
 * cdf[n] = 1, n > 0, and u is in [0, 1). Returns the last i with cdf[i] <= u; its interval
 * [cdf[i], cdf[i+1]) contains u, so an empty interval (zero pmf) is never returned. */
inline DiscreteSample sample_discrete_cdf(global const float* cdf, uint n, float u) {
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
    return s;
}

/* Probability that sample_discrete_cdf returns i < n. */
inline float discrete_cdf_pmf(global const float* cdf, uint i) { return cdf[i + 1u] - cdf[i]; }

/* Alias method (Walker 1977; Vose 1991) with one number on the 2^-24 grid: k = u·2^24 and
 * k·n (exact in 64 bits) give the bucket, k·n / 2^24, and the coin, k·n mod 2^24, both integers,
 * so the probability of each outcome is a count of k values that the host's build_alias_table
 * makes the reported pmf. n > 0 and u in [0, 1). Entries of zero pmf (zero weight) have
 * threshold 0 and are never an alias. */
inline DiscreteSample sample_discrete_alias(global const AliasEntry* table, uint n, float u) {
    uint k = min((uint)(u * 16777216.0f), 16777215u);
    ulong t = (ulong)k * (ulong)n;
    uint bucket = (uint)(t >> 24);
    uint coin = (uint)(t & 0xfffffful);
    AliasEntry e = table[bucket];
    DiscreteSample s;
    s.index = coin < e.threshold ? bucket : e.alias;
    s.pmf = table[s.index].pmf;
    return s;
}

/* Probability that sample_discrete_alias returns i < n. */
inline float discrete_alias_pmf(global const AliasEntry* t, uint i) { return t[i].pmf; }

#endif
