// Pearson's χ² test with Wilson–Hilferty critical values, shared by the sampling and BSDF
// suites (tests/test_sampling.cpp, tests/test_materials.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace mcrt::test {

// z with P(Z > z) = p for a standard normal Z, by bisection on the complementary error function.
inline double normal_upper_quantile(double p) {
    double lo = -40.0, hi = 40.0;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// Upper-α quantile of χ² with k degrees of freedom, Wilson & Hilferty 1931: (χ²/k)^(1/3) is
// nearly normal with mean 1 − 2/(9k) and variance 2/(9k).
inline double chi2_critical(double k, double alpha) {
    double v = 2.0 / (9.0 * k);
    return k * std::pow(1.0 - v + normal_upper_quantile(alpha) * std::sqrt(v), 3.0);
}

struct Chi2 {
    double statistic = 0, critical = 0;
    int dof = 0;
};

// Pearson's χ² of observed against expected counts, cells with expected < 5 pooled (smallest
// first, as Mitsuba's χ² test does), at significance alpha.
inline Chi2 chi2_test(const std::string& name, const std::vector<double>& observed,
                      const std::vector<double>& expected, double alpha) {
    std::vector<size_t> order(observed.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](size_t i, size_t j) { return expected[i] < expected[j]; });
    std::vector<std::pair<double, double>> cells;
    double pool_o = 0, pool_e = 0;
    for (size_t i : order) {
        pool_o += observed[i];
        pool_e += expected[i];
        if (pool_e >= 5.0) {
            cells.emplace_back(pool_o, pool_e);
            pool_o = pool_e = 0;
        }
    }
    if (pool_o > 0 || pool_e > 0) {
        if (cells.empty()) cells.emplace_back(0.0, 0.0);
        cells.back().first += pool_o;
        cells.back().second += pool_e;
    }
    Chi2 r;
    for (auto [o, e] : cells) r.statistic += e > 0 ? (o - e) * (o - e) / e : (o > 0 ? 1e30 : 0);
    r.dof = int(cells.size()) - 1;
    r.critical = chi2_critical(std::max(r.dof, 1), alpha);
    std::printf("chi2 %-44s statistic %10.1f  dof %5d  critical %8.1f\n", name.c_str(), r.statistic,
                r.dof, r.critical);
    return r;
}

}  // namespace mcrt::test
