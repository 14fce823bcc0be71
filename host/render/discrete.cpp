#include "render/discrete.h"

#include <cmath>
#include <string>

#include "common/error.h"

namespace mcrt {

namespace {

// Σweights, after checking each weight.
double checked_total(const std::vector<double>& weights) {
    double total = 0.0;
    for (size_t i = 0; i < weights.size(); ++i) {
        if (!std::isfinite(weights[i]) || weights[i] < 0.0)
            throw InputError("discrete distribution: weight " + std::to_string(i) + " is " +
                             std::to_string(weights[i]) + ", not a finite non-negative number");
        total += weights[i];
    }
    if (!std::isfinite(total))
        throw InputError("discrete distribution: the weights' sum overflows");
    return total;
}

}  // namespace

std::vector<float> build_cdf(const std::vector<double>& weights) {
    double total = checked_total(weights);
    if (total == 0.0) return {0.0f};
    size_t n = weights.size(), last = 0;  // last positive weight
    for (size_t i = 0; i < n; ++i)
        if (weights[i] > 0.0) last = i;
    std::vector<float> cdf(n + 1, 1.0f);  // entries from last + 1 on are exactly 1
    cdf[0] = 0.0f;
    double running = 0.0;
    for (size_t i = 0; i < last; ++i) {
        running += weights[i];
        cdf[i + 1] = std::fmin(float(running / total), 1.0f);
    }
    return cdf;
}

std::vector<gpu::AliasEntry> build_alias_table(const std::vector<double>& weights) {
    double total = checked_total(weights);
    if (total == 0.0) return {};
    size_t n = weights.size();
    std::vector<gpu::AliasEntry> table(n);
    // Scaled probabilities p_i = n·w_i/Σw, mean 1; buckets below 1 are topped up by an alias.
    std::vector<double> p(n);
    std::vector<size_t> small, large;
    size_t heaviest = 0;
    for (size_t i = 0; i < n; ++i) {
        p[i] = weights[i] / total * double(n);
        (p[i] < 1.0 ? small : large).push_back(i);
        if (weights[i] > weights[heaviest]) heaviest = i;
        table[i] = {0.0f, gpu::uint(i), float(weights[i] / total), 0u};
    }
    while (!small.empty() && !large.empty()) {
        size_t s = small.back(), l = large.back();
        small.pop_back();
        table[s].prob = float(p[s]);
        table[s].alias = gpu::uint(l);
        // p_l − (1 − p_s), summed in this order to lose less (Schwarz, "Darts, Dice, and Coins").
        p[l] = (p[l] + p[s]) - 1.0;
        if (p[l] < 1.0) {
            large.pop_back();
            small.push_back(l);
        }
    }
    // What is left is 1 up to rounding, and keeps its whole bucket; a zero weight never does.
    for (size_t i : large) table[i].prob = 1.0f;
    for (size_t i : small) {
        bool empty = weights[i] == 0.0;
        table[i].prob = empty ? 0.0f : 1.0f;
        table[i].alias = gpu::uint(empty ? heaviest : i);
    }
    return table;
}

}  // namespace mcrt
