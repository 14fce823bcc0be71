// Pearson's χ² test with Wilson–Hilferty critical values, and the expected counts of a direction
// grid, shared by the sampling, BSDF and glass suites (tests/sampling/test_sampling.cpp,
// tests/materials/test_materials.cpp, tests/materials/test_glass.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
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

// The expected fraction of samples in each cell of a direction grid (HemisphereGrid,
// SphereGrid: nt × np cells in θ and φ, a last cell for what is left): ∫ pdf_w over each cell by
// the midpoint rule on m × m points weighted by sinθ, again on fine × fine points in the cells
// where the pdf varies by more than 10% between their points (a grazing view's lobe is a thin
// sliver, Jacobian 4 wo·h). `pdf_of(directions)` returns the pdf at each direction.
template <class Grid, class PdfOf>
std::vector<double> expected_cell_fractions(const Grid& g, int m, int fine, const PdfOf& pdf_of) {
    auto integrate = [&](const std::vector<int>& cells, int q, std::vector<double>* spread) {
        std::vector<glm::dvec3> w;
        std::vector<double> weight;
        w.reserve(cells.size() * q * q);
        for (int cell : cells) {
            int it = cell / g.np, ip = cell % g.np;
            for (int a = 0; a < q; ++a)
                for (int b = 0; b < q; ++b) {
                    double t = (it + (a + 0.5) / q) * g.dt(), p = (ip + (b + 0.5) / q) * g.dp();
                    w.push_back(g.direction(t, p));
                    weight.push_back(std::sin(t) * g.dt() * g.dp() / (q * q));
                }
        }
        const std::vector<float> pdf = pdf_of(w);
        std::vector<double> out(cells.size(), 0.0);
        if (spread) spread->assign(cells.size(), 0.0);
        for (size_t c = 0; c < cells.size(); ++c) {
            double lo = 1e300, hi = 0;
            for (int k = 0; k < q * q; ++k) {
                size_t j = c * q * q + k;
                out[c] += pdf[j] * weight[j];
                lo = std::min(lo, double(pdf[j]));
                hi = std::max(hi, double(pdf[j]));
            }
            if (spread) (*spread)[c] = hi > 0 ? (hi - lo) / hi : 0.0;
        }
        return out;
    };
    std::vector<int> all(g.nt * g.np);
    std::iota(all.begin(), all.end(), 0);
    std::vector<double> spread;
    std::vector<double> coarse = integrate(all, m, &spread);
    std::vector<int> refine;
    for (int c : all)
        if (spread[c] > 0.1) refine.push_back(c);
    for (size_t begin = 0; begin < refine.size(); begin += 256) {
        std::vector<int> part(refine.begin() + begin,
                              refine.begin() + std::min(refine.size(), begin + 256));
        std::vector<double> v = integrate(part, fine, nullptr);
        for (size_t k = 0; k < part.size(); ++k) coarse[part[k]] = v[k];
    }
    std::vector<double> e(g.cells(), 0.0);
    double total = 0;
    for (int c : all) total += (e[c] = coarse[c]);
    e.back() = std::max(0.0, 1.0 - total);
    return e;
}

}  // namespace mcrt::test
