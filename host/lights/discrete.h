// Discrete distributions for the kernels' samplers (kernels/sampling/discrete.cl): a CDF for
// inversion by binary search and an alias table, both built from non-negative weights.
#pragma once

#include <vector>

#include "shared_types.h"

namespace mcrt {

// CDF of weights / Σweights as n + 1 floats on the 2^-24 grid of the kernels' random numbers:
// cdf[0] = 0, cdf[n] = 1, each interval a whole number of 2^-24 steps within two steps of its
// share, so that the pmf the kernels read (cdf[i+1] − cdf[i]) is exactly the probability that
// a grid-uniform u selects i. A zero weight gives an empty interval, never sampled; every
// positive weight gets at least one step, however small (up to 2^24 positive weights; beyond
// that the smallest may get none). The independent and Sobol samplers give such u; the
// stratified one's (stratum + jitter)/N is finer, and the width is then the probability up to
// float rounding. Empty or all-zero weights give {0}: a distribution of no
// entries, which callers must not sample. Throws InputError on a negative or non-finite
// weight, or a non-finite sum.
std::vector<float> build_cdf(const std::vector<double>& weights);

// Alias table of weights / Σweights (Vose 1991, "A linear algorithm for generating random
// numbers with a given distribution") on the same 2^-24 grid, one entry per weight: each pmf is
// a whole number of 2^-24 steps within about n·2^-24 of its share, and exactly the probability
// that the kernels' sampler returns it for a grid-uniform u. Zero-weight entries get threshold
// 0 and are never the alias of another; every positive weight is reachable (up to 2^24
// entries). Empty or all-zero weights give an empty table. Throws as build_cdf.
std::vector<gpu::AliasEntry> build_alias_table(const std::vector<double>& weights);

}  // namespace mcrt
