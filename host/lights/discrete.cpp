#include "lights/discrete.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
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
    const size_t n = weights.size();
    // The kernels' u is a multiple of 2^-24 (kernels/sampling/rng.cl), so the CDF is built on that
    // grid: entry i gets units[i] steps of 2^-24, every positive weight at least one, so that every
    // light with power is reachable and its pmf, cdf[i+1] − cdf[i] = units[i]·2^-24, is exact
    // in float and is the probability of selecting it (PBRT 3rd ed. 13.3.1 with its rounding
    // made exact). Largest remainders settle the total at 2^24 (Hamilton's apportionment).
    constexpr int64_t kGrid = int64_t(1) << 24;
    size_t positive = 0;
    for (double w : weights) positive += w > 0.0;
    std::vector<int64_t> units(n, 0);
    std::vector<double> ideal(n, 0.0);
    int64_t assigned = 0;
    const bool room = positive <= size_t(kGrid);  // else the smallest lights cannot all fit
    for (size_t i = 0; i < n; ++i) {
        if (weights[i] <= 0.0) continue;
        ideal[i] = double(kGrid) * (weights[i] / total);
        units[i] = int64_t(std::floor(ideal[i]));
        if (room && units[i] == 0) units[i] = 1;
        assigned += units[i];
    }
    if (assigned != kGrid) {
        // Entries ordered by what they still miss (ideal − units): give to the front, take from
        // the back (never below one unit when there is room, never from a zero weight).
        std::vector<size_t> order;
        for (size_t i = 0; i < n; ++i)
            if (weights[i] > 0.0) order.push_back(i);
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
            return ideal[a] - double(units[a]) > ideal[b] - double(units[b]);
        });
        const int64_t floor_units = room ? 1 : 0;
        while (assigned < kGrid)
            for (size_t k = 0; k < order.size() && assigned < kGrid; ++k)
                ++units[order[k]], ++assigned;
        while (assigned > kGrid) {
            bool took = false;
            for (size_t k = order.size(); k-- > 0 && assigned > kGrid;) {
                if (units[order[k]] <= floor_units) continue;
                --units[order[k]], --assigned, took = true;
            }
            if (!took) throw RuntimeError("discrete distribution: cannot apportion the CDF");
        }
    }
    std::vector<float> cdf(n + 1);
    cdf[0] = 0.0f;
    int64_t running = 0;
    for (size_t i = 0; i < n; ++i) {
        running += units[i];
        cdf[i + 1] = float(running) * 0x1.0p-24f;  // exact: running ≤ 2^24
    }
    return cdf;
}

std::vector<gpu::AliasEntry> build_alias_table(const std::vector<double>& weights) {
    double total = checked_total(weights);
    if (total == 0.0) return {};
    const size_t n = weights.size();
    // Vose's construction in double: bucket i keeps i with probability prob[i], else alias[i].
    // Scaled probabilities p_i = n·w_i/Σw, mean 1; buckets below 1 are topped up by an alias.
    std::vector<double> p(n), prob(n, 0.0);
    std::vector<uint32_t> alias(n);
    std::vector<size_t> small, large;
    size_t heaviest = 0;
    for (size_t i = 0; i < n; ++i) {
        p[i] = weights[i] / total * double(n);
        (p[i] < 1.0 ? small : large).push_back(i);
        if (weights[i] > weights[heaviest]) heaviest = i;
        alias[i] = uint32_t(i);
    }
    while (!small.empty() && !large.empty()) {
        size_t s = small.back(), l = large.back();
        small.pop_back();
        prob[s] = p[s];
        alias[s] = uint32_t(l);
        // p_l − (1 − p_s), summed in this order to lose less (Schwarz, "Darts, Dice, and Coins").
        p[l] = (p[l] + p[s]) - 1.0;
        if (p[l] < 1.0) {
            large.pop_back();
            small.push_back(l);
        }
    }
    // What is left is 1 up to rounding, and keeps its whole bucket; a zero weight never does.
    for (size_t i : large) prob[i] = 1.0;
    for (size_t i : small) {
        bool empty = weights[i] == 0.0;
        prob[i] = empty ? 0.0 : 1.0;
        alias[i] = uint32_t(empty ? heaviest : i);
    }

    // On the kernels' grid (kernels/sampling/discrete.cl): k in [0, 2^24) falls in bucket b when
    // b·2^24 ≤ k·n < (b+1)·2^24, i.e. for c_b values of k from ceil(b·2^24/n), whose coins
    // k·n − b·2^24 run from s_b < n in steps of n. A threshold keeping d_b of them keeps i with
    // probability d_b/2^24 and gives alias the other c_b − d_b; d_b = round(prob·c_b), at least
    // one for a positive weight (so every light with power is reachable). The pmf is counted
    // from these integers, so it is exactly the probability the kernels sample with.
    constexpr uint64_t kGrid = uint64_t(1) << 24;
    std::vector<uint64_t> count(n, 0);
    std::vector<gpu::AliasEntry> table(n);
    for (size_t b = 0; b < n; ++b) {
        const uint64_t first = (uint64_t(b) * kGrid + n - 1) / n;    // ceil(b·2^24 / n)
        const uint64_t end = (uint64_t(b + 1) * kGrid + n - 1) / n;  // ceil((b+1)·2^24 / n)
        const uint64_t c = end - first, start = first * n - uint64_t(b) * kGrid;
        uint64_t d = weights[b] > 0.0 ? uint64_t(std::llround(prob[b] * double(c))) : 0;
        if (weights[b] > 0.0 && d == 0 && c > 0) d = 1;
        d = std::min(d, c);
        table[b].threshold = d == 0 ? 0u : uint32_t(start + (d - 1) * n + 1);
        table[b].alias = alias[b];
        count[b] += d;
        count[alias[b]] += c - d;
    }
    for (size_t i = 0; i < n; ++i) table[i].pmf = float(count[i]) * 0x1.0p-24f;  // exact
    return table;
}

}  // namespace mcrt
