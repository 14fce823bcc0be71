// The sampling routines of kernels/sampling/sampling.cl, discrete.cl and frame.cl run on the device
// (entry points in tests/kernels/sampling_test.cl): each pdf integrates to 1, χ² tests of samples
// against the pdf twin, inverses round-trip, discrete samplers report their own pmf, and the
// Fibonacci spiral converges faster than uniform sampling.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/glm.hpp>
#include <numeric>
#include <random>

#include "chi2.h"
#include "cl/cl_error.h"
#include "cl/program.h"
#include "device_support.h"
#include "kernel_program.h"
#include "lights/discrete.h"
#include "lights/light_tree.h"

using namespace mcrt;
using namespace mcrt::test;
using glm::dvec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Every χ² test of this file shares a family-wise significance of 1% (Bonferroni).
constexpr int kChi2Tests = 22;
constexpr double kAlpha = 0.01 / kChi2Tests;
constexpr size_t kSamples = 1000000;

// Direction kinds of sampling_test.cl.
enum WarpKind : cl_uint { kUniform = 0, kCosine = 1, kSphericalTriangle = 2, kFibonacci = 3 };

// ---- Device ---------------------------------------------------------------------------------

using Device = KernelProgram;

Device& device() {
    static Device d("sampling_test.cl", "-D SAMPLER_INDEPENDENT");
    return d;
}

cl_float4 f4(const dvec3& v) { return {{float(v.x), float(v.y), float(v.z), 0.0f}}; }
dvec3 d3(const cl_float4& v) { return dvec3(v.s[0], v.s[1], v.s[2]); }

// A spherical triangle of unit vertices (the device gets them rounded to float).
struct SphericalTriangle {
    dvec3 a{0, 0, 1}, b{0, 0, 1}, c{0, 0, 1};
};

// Samples of a direction kind, as (w, pdf_w); u hashed from (k, seed) on the device.
std::vector<cl_float4> warp(WarpKind kind, const SphericalTriangle& t, size_t n, cl_uint seed) {
    Device& d = device();
    cl::Buffer out = d.output<cl_float4>(n);
    d.run("warp_directions", n, cl_uint(kind), f4(t.a), f4(t.b), f4(t.c), cl_uint(n), seed, out);
    return d.read<cl_float4>(out, n);
}

std::vector<cl_float4> warp_from_u(WarpKind kind, const SphericalTriangle& t,
                                   const std::vector<cl_float2>& u) {
    Device& d = device();
    cl::Buffer in = d.buffer(u), out = d.output<cl_float4>(u.size());
    d.run("warp_directions_from_u", u.size(), cl_uint(kind), f4(t.a), f4(t.b), f4(t.c),
          cl_uint(u.size()), in, out);
    return d.read<cl_float4>(out, u.size());
}

std::vector<cl_float2> invert(WarpKind kind, const SphericalTriangle& t,
                              const std::vector<cl_float4>& w) {
    Device& d = device();
    cl::Buffer in = d.buffer(w), out = d.output<cl_float2>(w.size());
    d.run("invert_directions", w.size(), cl_uint(kind), f4(t.a), f4(t.b), f4(t.c),
          cl_uint(w.size()), in, out);
    return d.read<cl_float2>(out, w.size());
}

std::vector<float> pdf_w(WarpKind kind, const SphericalTriangle& t,
                         const std::vector<cl_float4>& w) {
    Device& d = device();
    cl::Buffer in = d.buffer(w), out = d.output<float>(w.size());
    d.run("pdf_directions", w.size(), cl_uint(kind), f4(t.a), f4(t.b), f4(t.c), cl_uint(w.size()),
          in, out);
    return d.read<float>(out, w.size());
}

float device_solid_angle(const SphericalTriangle& t) {
    Device& d = device();
    cl::Buffer out = d.output<float>(1);
    d.run("solid_angle", 1, f4(t.a), f4(t.b), f4(t.c), out);
    return d.read<float>(out, 1)[0];
}

// ---- χ² test ----------------------------------------------------------------------------

Chi2 chi2_test(const std::string& name, const std::vector<double>& observed,
               const std::vector<double>& expected) {
    return mcrt::test::chi2_test(name, observed, expected, kAlpha);
}

// ---- Direction cells --------------------------------------------------------------------

// Cells of equal (z, φ') size over a window, φ' = φ − phi_center in (−π, π], so dω = dz dφ';
// cell nz·np holds every direction outside the window.
struct Grid {
    double z0 = -1, z1 = 1, p0 = -kPi, p1 = kPi, phi_center = 0;
    int nz = 1, np = 1;
    double edge_tolerance = 0;  // values this close outside the window are clamped into it

    int cells() const { return nz * np + 1; }
    double dz() const { return (z1 - z0) / nz; }
    double dp() const { return (p1 - p0) / np; }

    int cell_of(const dvec3& w) const {
        double z = w.z, p = std::remainder(std::atan2(w.y, w.x) - phi_center, 2 * kPi);
        if (z < z0 && z > z0 - edge_tolerance) z = z0;
        if (z >= z1 && z < z1 + edge_tolerance) z = std::nextafter(z1, z0);
        int iz = int(std::floor((z - z0) / dz())), ip = int(std::floor((p - p0) / dp()));
        if (iz < 0 || iz >= nz || ip < 0 || ip >= np) return nz * np;
        return iz * np + ip;
    }

    dvec3 direction(double z, double p) const {
        double r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = p + phi_center;
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    }
};

struct CellIntegrals {
    std::vector<double> integral;  // ∫ pdf_w dω over each window cell
    double error_bound = 0;        // worst-case error of the midpoint rule at discontinuities
    double error_sigma = 0;        // its likely size (see integrate_cells)
};

// ∫ pdf_w over each cell by the midpoint rule on m1 × m1 points; cells where the pdf is not
// constant, and their neighbours, again on m2 × m2 points (pdf_w evaluated on the device). A
// midpoint sub-cell next to one of different value may hold a discontinuity and be wrong by at
// most its whole mass m: the sum of those masses bounds the error. A discontinuity crossing a
// sub-cell at a random offset makes its error uniform in ±m/2, of variance m²/12, independent
// from one sub-cell to the next: error_sigma = √(Σ m²/12) is the error's likely size.
CellIntegrals integrate_cells(WarpKind kind, const SphericalTriangle& t, const Grid& g, int m1,
                              int m2, const std::vector<dvec3>& boundary = {}) {
    auto points = [&](const std::vector<int>& cells, int m) {
        std::vector<cl_float4> w;
        w.reserve(cells.size() * m * m);
        for (int cell : cells) {
            int iz = cell / g.np, ip = cell % g.np;
            for (int sz = 0; sz < m; ++sz)
                for (int sp = 0; sp < m; ++sp)
                    w.push_back(f4(g.direction(g.z0 + (iz + (sz + 0.5) / m) * g.dz(),
                                               g.p0 + (ip + (sp + 0.5) / m) * g.dp())));
        }
        return w;
    };
    CellIntegrals r;
    r.integral.assign(g.nz * g.np, 0.0);
    std::vector<int> all(g.nz * g.np);
    std::iota(all.begin(), all.end(), 0);
    std::vector<float> v1 = pdf_w(kind, t, points(all, m1));
    std::vector<char> refine(all.size(), 0);
    auto refine_around = [&](int cell) {
        int iz = cell / g.np, ip = cell % g.np;
        for (int jz = std::max(iz - 1, 0); jz <= std::min(iz + 1, g.nz - 1); ++jz)
            for (int jp = std::max(ip - 1, 0); jp <= std::min(ip + 1, g.np - 1); ++jp)
                refine[jz * g.np + jp] = 1;
    };
    for (int cell : all) {
        const float* v = &v1[size_t(cell) * m1 * m1];
        double sum = 0;
        bool constant = true;
        for (int k = 0; k < m1 * m1; ++k) sum += v[k], constant = constant && v[k] == v[0];
        r.integral[cell] = sum * g.dz() * g.dp() / (m1 * m1);
        if (!constant) refine_around(cell);
    }
    // A discontinuity may cross a cell between its m1 × m1 points (near the grid's poles, a
    // cell is long and thin): the cells of points along it are refined too.
    for (const dvec3& w : boundary) {
        int cell = g.cell_of(w);
        if (cell < g.nz * g.np) refine_around(cell);
    }
    std::vector<int> fine;
    for (int cell : all)
        if (refine[cell]) fine.push_back(cell);
    const size_t chunk = std::max<size_t>(1, (size_t(1) << 21) / (m2 * m2));
    double sub_area = g.dz() * g.dp() / (m2 * m2);
    for (size_t begin = 0; begin < fine.size(); begin += chunk) {
        std::vector<int> cells(fine.begin() + begin,
                               fine.begin() + std::min(fine.size(), begin + chunk));
        std::vector<float> v2 = pdf_w(kind, t, points(cells, m2));
        for (size_t c = 0; c < cells.size(); ++c) {
            const float* v = &v2[c * m2 * m2];
            double sum = 0;
            for (int sz = 0; sz < m2; ++sz)
                for (int sp = 0; sp < m2; ++sp) {
                    float x = v[sz * m2 + sp];
                    sum += x;
                    bool mixed = (sz > 0 && v[(sz - 1) * m2 + sp] != x) ||
                                 (sz + 1 < m2 && v[(sz + 1) * m2 + sp] != x) ||
                                 (sp > 0 && v[sz * m2 + sp - 1] != x) ||
                                 (sp + 1 < m2 && v[sz * m2 + sp + 1] != x);
                    if (mixed) {
                        r.error_bound += sub_area * x;
                        r.error_sigma += (sub_area * x) * (sub_area * x) / 12.0;
                    }
                }
            r.integral[cells[c]] = sum * sub_area;
        }
    }
    r.error_sigma = std::sqrt(r.error_sigma);
    return r;
}

// χ² of kSamples device samples of a direction kind against its pdf twin integrated over the
// grid's cells. Also checks every sample is a finite unit vector of positive pdf (a few
// samples on a triangle's edge may round outside it: at most max_zero_pdf of them).
double inside_margin(const SphericalTriangle& t, const dvec3& w);
std::vector<dvec3> edge_points(const SphericalTriangle& t);

Chi2 direction_chi2(const std::string& name, WarpKind kind, const SphericalTriangle& t,
                    const Grid& g, cl_uint seed, size_t max_zero_pdf = 0) {
    std::vector<cl_float4> samples = warp(kind, t, kSamples, seed);
    std::vector<double> observed(g.cells(), 0.0), expected(g.cells(), 0.0);
    size_t bad = 0, zero_pdf = 0;
    for (const cl_float4& s : samples) {
        dvec3 w = d3(s);
        if (!std::isfinite(s.s[3]) || !(std::abs(glm::length(w) - 1.0) < 1e-5)) ++bad;
        if (!(s.s[3] > 0.0f)) ++zero_pdf;
        observed[g.cell_of(w)] += 1;
    }
    CHECK(bad == 0);
    CHECK(zero_pdf <= max_zero_pdf);
    CellIntegrals cells = integrate_cells(
        kind, t, g, 4, 64, kind == kSphericalTriangle ? edge_points(t) : std::vector<dvec3>{});
    double total = 0;
    for (size_t c = 0; c < cells.integral.size(); ++c) {
        expected[c] = cells.integral[c] * double(kSamples);
        total += expected[c];
    }
    expected.back() = std::max(0.0, double(kSamples) - total);
    Chi2 r = chi2_test(name, observed, expected);
    CHECK(r.statistic < r.critical);
    return r;
}

// ---- Spherical triangles ----------------------------------------------------------------

dvec3 spherical(double theta, double phi) {
    return dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

double solid_angle(const SphericalTriangle& t) {  // Van Oosterom & Strackee 1983
    return 2.0 * std::atan2(std::abs(glm::dot(t.a, glm::cross(t.b, t.c))),
                            1.0 + glm::dot(t.a, t.b) + glm::dot(t.b, t.c) + glm::dot(t.c, t.a));
}

// Vertices at angular distance ρ from the centre, at the given azimuths about it, with ρ set by
// bisection so that the triangle subtends omega.
SphericalTriangle triangle_of_solid_angle(double theta, double phi, double omega,
                                          const double azimuth[3]) {
    dvec3 n = spherical(theta, phi), e1 = glm::normalize(glm::cross(dvec3(0, 0, 1), n)),
          e2 = glm::cross(n, e1);
    auto make = [&](double rho) {
        dvec3 v[3];
        for (int k = 0; k < 3; ++k)
            v[k] = std::cos(rho) * n +
                   std::sin(rho) * (std::cos(azimuth[k]) * e1 + std::sin(azimuth[k]) * e2);
        return SphericalTriangle{v[0], v[1], v[2]};
    };
    double lo = 0, hi = kPi / 2;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (solid_angle(make(mid)) < omega ? lo : hi) = mid;
    }
    return make(0.5 * (lo + hi));
}

// A sliver: a and b far apart, c off the middle of their arc by `height` radians.
SphericalTriangle sliver(double height) {
    dvec3 a = spherical(1.1, 0.4), b = spherical(1.3, 1.0);
    dvec3 m = glm::normalize(a + b), n = glm::normalize(glm::cross(a, b));
    return {a, b, glm::normalize(m + height * n)};
}

// Signed angular distance of w inside the triangle's three great circles (negative outside).
double inside_margin(const SphericalTriangle& t, const dvec3& w) {
    double s = glm::dot(t.a, glm::cross(t.b, t.c)) >= 0 ? 1.0 : -1.0;
    double m = 1e30;
    for (auto [p, q] : {std::pair{t.a, t.b}, {t.b, t.c}, {t.c, t.a}})
        m = std::min(m, s * glm::dot(w, glm::normalize(glm::cross(p, q))));
    return m;
}

// Points every ~1e-4 rad (at most) along the triangle's edges, where its pdf is discontinuous.
std::vector<dvec3> edge_points(const SphericalTriangle& t) {
    std::vector<dvec3> points;
    for (auto [p, q] : {std::pair{t.a, t.b}, {t.b, t.c}, {t.c, t.a}}) {
        int steps = 1000 + int(glm::length(q - p) / 1e-4);
        for (int k = 0; k <= steps; ++k)
            points.push_back(glm::normalize(p + (q - p) * (double(k) / steps)));
    }
    return points;
}

// A window around the triangle in (z, φ'), from dense points along its edges, with a margin.
Grid grid_around(const SphericalTriangle& t, int nz, int np) {
    Grid g;
    g.nz = nz, g.np = np;
    dvec3 centre = glm::normalize(t.a + t.b + t.c);
    g.phi_center = std::atan2(centre.y, centre.x);
    if (inside_margin(t, dvec3(0, 0, 1)) > 0 || inside_margin(t, dvec3(0, 0, -1)) > 0) return g;
    double zlo = 2, zhi = -2, plo = 4, phi = -4;
    for (auto [p, q] : {std::pair{t.a, t.b}, {t.b, t.c}, {t.c, t.a}})
        for (int k = 0; k <= 4000; ++k) {
            dvec3 w = glm::normalize(p + (q - p) * (k / 4000.0));
            double pw = std::remainder(std::atan2(w.y, w.x) - g.phi_center, 2 * kPi);
            zlo = std::min(zlo, w.z), zhi = std::max(zhi, w.z);
            plo = std::min(plo, pw), phi = std::max(phi, pw);
        }
    double mz = 0.03 * (zhi - zlo), mp = 0.03 * (phi - plo);
    g.z0 = std::max(-1.0, zlo - mz), g.z1 = std::min(1.0, zhi + mz);
    g.p0 = std::max(-kPi, plo - mp), g.p1 = std::min(kPi, phi + mp);
    return g;
}

const double kAzimuths[3] = {0.1, 2.3, 4.0};

SphericalTriangle large_triangle() { return triangle_of_solid_angle(1.1, 0.5, 1.0, kAzimuths); }
SphericalTriangle small_triangle() { return triangle_of_solid_angle(1.2, -2.0, 1e-3, kAzimuths); }
SphericalTriangle huge_triangle() { return triangle_of_solid_angle(0.9, 2.0, 4.0, kAzimuths); }

std::vector<cl_float2> random_u(size_t n, double lo, double hi, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<cl_float2> out(n);
    for (auto& x : out) x = {{float(u(rng)), float(u(rng))}};
    return out;
}

// max |u' − u| over the round trip u → w → u', the second coordinate taken modulo 1 when it
// is an azimuth.
double round_trip_u(WarpKind kind, const SphericalTriangle& t, const std::vector<cl_float2>& u,
                    bool azimuth) {
    std::vector<cl_float2> back = invert(kind, t, warp_from_u(kind, t, u));
    double worst = 0;
    for (size_t k = 0; k < u.size(); ++k) {
        double d0 = std::abs(back[k].s[0] - u[k].s[0]), d1 = back[k].s[1] - u[k].s[1];
        if (azimuth) d1 = std::remainder(d1, 1.0);
        worst = std::max({worst, d0, std::abs(d1)});
    }
    return worst;
}

// max over the round trip w → u → w' of |w' − w| / (1 + condition(w)).
template <typename Condition>
double round_trip_w(WarpKind kind, const SphericalTriangle& t, const std::vector<cl_float4>& w,
                    Condition condition) {
    std::vector<cl_float2> u = invert(kind, t, w);
    std::vector<cl_float4> back = warp_from_u(kind, t, u);
    double worst = 0;
    for (size_t k = 0; k < w.size(); ++k)
        worst = std::max(worst, glm::length(d3(back[k]) - d3(w[k])) / (1 + condition(d3(w[k]))));
    return worst;
}

double round_trip_w(WarpKind kind, const SphericalTriangle& t, const std::vector<cl_float4>& w) {
    return round_trip_w(kind, t, w, [](const dvec3&) { return 0.0; });
}

}  // namespace

// ---- Hemisphere ---------------------------------------------------------------------------

TEST_CASE("hemisphere pdfs integrate to 1 over the sphere", "[sampling]") {
    Grid sphere;
    sphere.nz = 64, sphere.np = 64;
    for (WarpKind kind : {kUniform, kCosine, kFibonacci}) {
        CellIntegrals c = integrate_cells(kind, {}, sphere, 4, 4);
        double total = std::accumulate(c.integral.begin(), c.integral.end(), 0.0);
        INFO("kind " << kind << " integral " << total);
        CHECK(std::abs(total - 1.0) < 1e-5);  // the midpoint rule is exact for pdfs linear in z
    }
}

TEST_CASE("hemisphere warps match their pdfs (chi2)", "[sampling]") {
    Grid hemisphere;
    hemisphere.z0 = 0, hemisphere.nz = 32, hemisphere.np = 64;
    direction_chi2("hemisphere uniform", kUniform, {}, hemisphere, 1);
    direction_chi2("hemisphere cosine", kCosine, {}, hemisphere, 2);
    // Each sample's pdf is the twin's value of what was returned.
    for (const cl_float4& s : warp(kCosine, {}, 1000, 3))
        CHECK(s.s[3] == Approx(s.s[2] / kPi).epsilon(1e-6));
    for (const cl_float4& s : warp(kUniform, {}, 1000, 3))
        CHECK(s.s[3] == Approx(0.5 / kPi).epsilon(1e-6));
}

TEST_CASE("hemisphere warps invert", "[sampling]") {
    std::vector<cl_float2> u = random_u(100000, 1e-3, 1.0 - 1e-3, 5);
    CHECK(round_trip_u(kUniform, {}, u, true) < 1e-4);
    CHECK(round_trip_u(kCosine, {}, u, false) < 1e-4);
    // The corners and the centre of the square, and its edges (z = 0 for the cosine warp).
    std::vector<cl_float2> edges = {
        {{0.5f, 0.5f}}, {{0.0f, 0.0f}}, {{0.0f, 0.7f}}, {{0.3f, 0.0f}}, {{0.999f, 0.999f}}};
    CHECK(round_trip_u(kCosine, {}, edges, false) < 1e-4);

    std::vector<cl_float4> w;
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> x(-1, 1);
    while (w.size() < 100000) {
        dvec3 v(x(rng), x(rng), x(rng));
        if (glm::length(v) > 1 || v.z < 1e-3 || glm::length(v) < 1e-3) continue;
        w.push_back(f4(glm::normalize(v)));
    }
    CHECK(round_trip_w(kUniform, {}, w) < 1e-5);
    // Near the horizon the cosine warp's u lies near 0 or 1 along the disk radius r, with
    // z = √((1 − r)(1 + r)) ≈ √(2(1 − r)): a rounding of u by 2^-24 moves r by 2^-23 and z by
    // 2^-23/z. The error is measured in units of that conditioning.
    CHECK(round_trip_w(kCosine, {}, w, [](const dvec3& v) { return 0x1.0p-23 / v.z / 1e-5; }) <
          1e-5);
}

// ---- Triangles ----------------------------------------------------------------------------

TEST_CASE("uniform triangle sampling is uniform (chi2) and inverts", "[sampling]") {
    Device& d = device();
    // Barycentric cells of a k × k grid over the unit square: a cell is inside the triangle
    // b1 + b2 <= 1 when i + j <= k − 2, half inside when i + j == k − 1 (the diagonal through
    // its corners), else outside. pdf_a = 1/area, so ∫pdf_a dA = 1 and a cell holds
    // (its area)/(1/2) of the samples.
    const int k = 64;
    cl::Buffer none = d.output<cl_float2>(1), b = d.output<cl_float2>(kSamples),
               back = d.output<cl_float2>(kSamples);
    d.run("warp_triangle", kSamples, cl_uint(kSamples), cl_uint(1), cl_uint(7), none, b, back);
    std::vector<cl_float2> bary = d.read<cl_float2>(b, kSamples);
    std::vector<double> observed(k * k + 1, 0.0), expected(k * k + 1, 0.0);
    size_t outside = 0;
    for (const cl_float2& s : bary) {
        double b1 = s.s[0], b2 = s.s[1];
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1 + 1e-6) ++outside;
        int i = std::min(int(b1 * k), k - 1), j = std::min(int(b2 * k), k - 1);
        observed[i * k + j] += 1;
    }
    CHECK(outside == 0);
    for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j)
            expected[i * k + j] = kSamples * 2.0 / (k * k) *
                                  (i + j <= k - 2   ? 1.0
                                   : i + j == k - 1 ? 0.5
                                                    : 0.0);
    Chi2 r = chi2_test("triangle uniform", observed, expected);
    CHECK(r.statistic < r.critical);

    std::vector<cl_float2> u = random_u(100000, 1e-3, 1 - 1e-3, 8);
    cl::Buffer in = d.buffer(u);
    d.run("warp_triangle", u.size(), cl_uint(u.size()), cl_uint(0), cl_uint(0), in, b, back);
    std::vector<cl_float2> u_back = d.read<cl_float2>(back, u.size());
    double worst = 0;
    for (size_t i = 0; i < u.size(); ++i)
        worst = std::max({worst, double(std::abs(u_back[i].s[0] - u[i].s[0])),
                          double(std::abs(u_back[i].s[1] - u[i].s[1]))});
    CHECK(worst < 1e-4);
}

TEST_CASE("spherical triangle solid angle matches double precision", "[sampling]") {
    for (const SphericalTriangle& t :
         {large_triangle(), small_triangle(), huge_triangle(), sliver(1e-3)}) {
        SphericalTriangle rounded{d3(f4(t.a)), d3(f4(t.b)), d3(f4(t.c))};
        double omega = solid_angle(rounded);
        INFO("omega " << omega);
        CHECK(device_solid_angle(t) == Approx(omega).epsilon(1e-4));
    }
}

TEST_CASE("spherical triangle pdf integrates to 1 over the sphere", "[sampling]") {
    Grid sphere;
    sphere.nz = 100, sphere.np = 200;
    for (const SphericalTriangle& t : {large_triangle(), huge_triangle()}) {
        CellIntegrals c = integrate_cells(kSphericalTriangle, t, sphere, 2, 32, edge_points(t));
        double total = std::accumulate(c.integral.begin(), c.integral.end(), 0.0);
        std::printf(
            "spherical triangle of %.5f sr: pdf integral %.7f, quadrature error "
            "%.1e (bound %.1e)\n",
            solid_angle(t), total, c.error_sigma, c.error_bound);
        CHECK(std::abs(total - 1.0) <= 4 * c.error_sigma + 1e-6);
    }
    // A small triangle, integrated over a window around it (the pdf is 0 outside: see chi2).
    SphericalTriangle small = small_triangle();
    CellIntegrals c = integrate_cells(kSphericalTriangle, small, grid_around(small, 40, 40), 4, 32,
                                      edge_points(small));
    double total = std::accumulate(c.integral.begin(), c.integral.end(), 0.0);
    std::printf(
        "spherical triangle of %.5f sr: pdf integral %.7f, quadrature error %.1e (bound "
        "%.1e)\n",
        solid_angle(small), total, c.error_sigma, c.error_bound);
    CHECK(std::abs(total - 1.0) <= 4 * c.error_sigma + 1e-6);
}

TEST_CASE("spherical triangle sampling matches its pdf (chi2)", "[sampling]") {
    // A few samples on an edge may round to the outside of it, where pdf_w is 0.
    SphericalTriangle t = large_triangle();
    direction_chi2("spherical triangle 1 sr", kSphericalTriangle, t, grid_around(t, 40, 40), 11,
                   10);
    t = small_triangle();
    direction_chi2("spherical triangle 1e-3 sr", kSphericalTriangle, t, grid_around(t, 40, 40), 12,
                   10);
    t = huge_triangle();
    direction_chi2("spherical triangle 4 sr", kSphericalTriangle, t, grid_around(t, 64, 64), 13,
                   10);
}

TEST_CASE("spherical triangle sampling inverts", "[sampling]") {
    std::vector<cl_float2> u = random_u(100000, 1e-2, 1 - 1e-2, 14);
    for (auto [name, t, tolerance] : {std::tuple{"1 sr", large_triangle(), 1e-4},
                                      {"4 sr", huge_triangle(), 1e-4},
                                      {"1e-3 sr", small_triangle(), 1e-4}}) {
        INFO(name);
        double worst_u = round_trip_u(kSphericalTriangle, t, u, false);
        std::vector<cl_float4> w = warp(kSphericalTriangle, t, 100000, 15);
        double worst_w = round_trip_w(kSphericalTriangle, t, w);
        double size = glm::length(t.a - t.b);
        std::printf("spherical triangle %s: round trip |du| %.2e, |dw|/edge %.2e\n", name, worst_u,
                    worst_w / size);
        CHECK(worst_u < tolerance);
        CHECK(worst_w < 1e-4 * size);
    }
}

TEST_CASE("spherical triangle sampling of large, small and sliver triangles stays inside",
          "[sampling]") {
    for (auto [name, t] :
         {std::pair{"1 sr", large_triangle()},
          {"4 sr", huge_triangle()},
          {"6 sr", triangle_of_solid_angle(0.5, 1.0, 6.0, kAzimuths)},
          {"1e-3 sr", small_triangle()},
          {"3e-4 sr", triangle_of_solid_angle(0.4, 1.0, 3e-4, kAzimuths)},
          {"1e-7 sr", triangle_of_solid_angle(1.0, 0.0, 1e-7, kAzimuths)},
          {"sliver 1e-4 rad", sliver(1e-4)},
          {"sliver 1e-6 rad", sliver(1e-6)},
          {"degenerate", SphericalTriangle{spherical(1, 1), spherical(1, 1), spherical(1.2, 1)}}}) {
        INFO(name);
        std::vector<cl_float4> w = warp(kSphericalTriangle, t, 200000, 16);
        // Inside up to float rounding of the vertices and of w, relative to the triangle.
        double size =
            std::max({glm::length(t.a - t.b), glm::length(t.b - t.c), glm::length(t.c - t.a)});
        size_t nan = 0, off_unit = 0, outside = 0;
        double worst = 1e30;
        for (const cl_float4& s : w) {
            dvec3 d = d3(s);
            if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) {
                ++nan;
                continue;
            }
            if (std::abs(glm::length(d) - 1) > 1e-5) ++off_unit;
            double m = inside_margin(t, d);
            worst = std::min(worst, m);
            if (m < -1e-6) ++outside;
        }
        std::printf("spherical triangle %-16s (edge %.1e): worst inside margin %.1e rad\n", name,
                    size, worst);
        CHECK(nan == 0);
        CHECK(off_unit == 0);
        CHECK(outside == 0);
    }
}

// ---- Spherical Fibonacci ------------------------------------------------------------------

std::vector<cl_float4> fibonacci_sets(cl_uint n, cl_uint sets, cl_uint seed, bool fixed,
                                      cl_float2 u) {
    Device& d = device();
    cl::Buffer out = d.output<cl_float4>(size_t(n) * sets);
    d.run("fibonacci_sets", size_t(n) * sets, n, sets, seed, cl_uint(fixed), u, out);
    return d.read<cl_float4>(out, size_t(n) * sets);
}

TEST_CASE("Fibonacci points fill one equal-solid-angle z-band each", "[sampling][fibonacci]") {
    for (cl_uint n : {1u, 37u, 1000u, 100000u}) {
        for (cl_float2 u : {cl_float2{{0.5f, 0.3f}}, cl_float2{{0.01f, 0.9f}}}) {
            std::vector<cl_float4> w = fibonacci_sets(n, 1, 0, true, u);
            size_t misplaced = 0;
            for (cl_uint i = 0; i < n; ++i) {
                double one_minus_z = 1.0 - w[i].s[2];
                if (int(std::floor(one_minus_z * n)) != int(i) || !(w[i].s[2] > 0)) ++misplaced;
            }
            INFO("n " << n);
            CHECK(misplaced == 0);
        }
    }
}

TEST_CASE("Fibonacci points are uniform in their band and on the hemisphere (chi2)",
          "[sampling][fibonacci]") {
    Device& d = device();
    const cl_uint n = 16, index = 5;
    cl::Buffer out = d.output<cl_float4>(kSamples);
    // Point `index` alone: uniform on its band, density n/(2π) there (closed form).
    d.run("fibonacci_samples", kSamples, n, index, cl_uint(kSamples), cl_uint(21), out);
    std::vector<cl_float4> w = d.read<cl_float4>(out, kSamples);
    Grid band;
    band.z0 = 1.0 - double(index + 1) / n, band.z1 = 1.0 - double(index) / n;
    band.nz = 20, band.np = 50, band.edge_tolerance = 1e-6;
    std::vector<double> observed(band.cells(), 0.0), expected(band.cells(), 0.0);
    for (const cl_float4& s : w) observed[band.cell_of(d3(s))] += 1;
    for (int c = 0; c < band.nz * band.np; ++c)
        expected[c] = double(kSamples) / (band.nz * band.np);
    Chi2 r = chi2_test("fibonacci point 5 of 16 on its band", observed, expected);
    CHECK(r.statistic < r.critical);
    CHECK(observed.back() == 0);

    // A point of random index: the twin's density 1/(2π) on the hemisphere.
    d.run("fibonacci_samples", kSamples, n, n, cl_uint(kSamples), cl_uint(22), out);
    w = d.read<cl_float4>(out, kSamples);
    Grid hemisphere;
    hemisphere.z0 = 0, hemisphere.nz = 32, hemisphere.np = 64;
    CellIntegrals cells = integrate_cells(kFibonacci, {}, hemisphere, 4, 4);
    std::vector<double> obs(hemisphere.cells(), 0.0), exp(hemisphere.cells(), 0.0);
    for (const cl_float4& s : w) {
        obs[hemisphere.cell_of(d3(s))] += 1;
        CHECK(s.s[3] == Approx(0.5 / kPi).epsilon(1e-6));
    }
    for (size_t c = 0; c < cells.integral.size(); ++c) exp[c] = cells.integral[c] * kSamples;
    r = chi2_test("fibonacci point of random index", obs, exp);
    CHECK(r.statistic < r.critical);
}

TEST_CASE("Fibonacci estimates converge faster than uniform sampling", "[sampling][fibonacci]") {
    // Integrands with known integrals over the hemisphere: ∫cosθ dω = π and ∫cosθ(1 + x) dω = π
    // (∫x cosθ dω = 0 by symmetry in φ). Under uniform sampling (z = cosθ uniform in [0, 1],
    // φ uniform) the estimator 2π·f has variance 4π²·Var[f]: Var[z] = 1/3 − 1/4 = 1/12, and
    // for f = z(1 + x), E[f²] = E[z²] + E[z²x²] = 1/3 + ½(1/3 − 1/5) = 2/5, E[f] = 1/2, so
    // Var[f] = 2/5 − 1/4 = 3/20. The standard error of the uniform mean of n is 2π·√(Var/n).
    const cl_uint sets = 64;
    auto rms_error = [&](cl_uint n, int integrand) {
        std::vector<cl_float4> w = fibonacci_sets(n, sets, 31, false, {{0, 0}});
        double sum_sq = 0;
        for (cl_uint s = 0; s < sets; ++s) {
            double sum = 0;
            for (cl_uint i = 0; i < n; ++i) {
                const cl_float4& p = w[size_t(s) * n + i];
                sum += integrand == 0 ? p.s[2] : p.s[2] * (1.0 + p.s[0]);
            }
            double e = 2 * kPi / n * sum - kPi;
            sum_sq += e * e;
        }
        return std::sqrt(sum_sq / sets);
    };
    const double variance[2] = {1.0 / 12.0, 3.0 / 20.0};
    for (int integrand : {0, 1}) {
        double e_small = rms_error(100, integrand), e_large = rms_error(10000, integrand);
        double uniform_error = 2 * kPi * std::sqrt(variance[integrand] / 10000);
        std::printf(
            "fibonacci integrand %d: rms error %.2e at n = 100, %.2e at n = 10^4 "
            "(uniform sampling: %.2e)\n",
            integrand, e_small, e_large, uniform_error);
        CHECK(e_large < 0.1 * uniform_error);
        CHECK(e_small / e_large > 10.0 * 1.5);  // n^-1/2 would give 10
    }
}

// ---- Discrete distributions ---------------------------------------------------------------

namespace {

std::vector<std::vector<double>> weight_vectors() {
    std::mt19937 rng(41);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<double> spread(20), plain(200);
    for (double& w : spread) w = u(rng) < 0.25 ? 0.0 : std::pow(10.0, 6.0 * u(rng));
    for (double& w : plain) w = u(rng) < 0.05 ? 0.0 : u(rng);
    plain.front() = plain.back() = 0.0;
    return {spread, plain, {0.0, 1.0, 1e6, 0.0, 5e5, 2.0, 0.0}};
}

}  // namespace

TEST_CASE("build_cdf and build_alias_table", "[sampling][discrete]") {
    CHECK(build_cdf({}) == std::vector<float>{0.0f});
    CHECK(build_cdf({0.0, 0.0}) == std::vector<float>{0.0f});
    CHECK(build_alias_table({}).empty());
    CHECK(build_alias_table({0.0, 0.0}).empty());
    CHECK_THROWS_AS(build_cdf({1.0, -1.0}), InputError);
    CHECK_THROWS_AS(build_alias_table({1.0, NAN}), InputError);
    CHECK(build_cdf({3.0}) == std::vector<float>{0.0f, 1.0f});

    // Weights 20 orders of magnitude apart: the light of 1e-20 of the power still gets one step
    // of the kernels' 2^-24 grid (a float CDF of w/Σw would give it an empty interval).
    std::vector<float> tiny = build_cdf({1e-12, 1.0, 1e-9, 0.0, 1e-20});
    REQUIRE(tiny.size() == 6);
    CHECK(tiny[1] - tiny[0] == 0x1.0p-24f);
    CHECK(tiny[3] - tiny[2] == 0x1.0p-24f);
    CHECK(tiny[4] == tiny[3]);
    CHECK(tiny[5] - tiny[4] == 0x1.0p-24f);
    CHECK(tiny[5] == 1.0f);

    std::vector<std::vector<double>> vectors = weight_vectors();
    vectors.push_back(std::vector<double>(3000, 1.0));  // 2^24 / 3000 is not whole: remainders
    vectors.back()[7] = 1e-15;
    for (const std::vector<double>& w : vectors) {
        double total = std::accumulate(w.begin(), w.end(), 0.0);
        std::vector<float> cdf = build_cdf(w);
        REQUIRE(cdf.size() == w.size() + 1);
        CHECK(cdf.front() == 0.0f);
        CHECK(cdf.back() == 1.0f);
        for (size_t i = 0; i < w.size(); ++i) {
            // On the grid of u (kernels/sampling/rng.cl), so the interval's width is exactly the
            // probability that u falls in it; positive weights are never left out.
            CHECK(double(cdf[i + 1]) * 0x1.0p24 == std::floor(double(cdf[i + 1]) * 0x1.0p24));
            if (w[i] == 0) CHECK(cdf[i] == cdf[i + 1]);
            if (w[i] > 0) CHECK(cdf[i] < cdf[i + 1]);
            CHECK(std::abs((cdf[i + 1] - cdf[i]) - w[i] / total) <= 0x1.0p-23);
        }
        // Every k of the kernels' 2^24 grid through sample_discrete_alias's integer mapping
        // (kernels/sampling/discrete.cl): the count of k giving i is the table's pmf · 2^24,
        // exactly.
        std::vector<gpu::AliasEntry> table = build_alias_table(w);
        REQUIRE(table.size() == w.size());
        const uint64_t n = w.size();
        std::vector<uint64_t> hits(n, 0);
        for (uint64_t k = 0; k < (uint64_t(1) << 24); ++k) {
            const uint64_t t = k * n, bucket = t >> 24, coin = t & 0xffffffu;
            const gpu::AliasEntry& e = table[bucket];
            ++hits[coin < e.threshold ? bucket : e.alias];
        }
        for (size_t i = 0; i < n; ++i) {
            INFO("entry " << i << " of " << n << ", weight " << w[i]);
            REQUIRE(table[i].alias < n);
            CHECK(double(table[i].pmf) * 0x1.0p24 == double(hits[i]));
            if (w[i] == 0) CHECK(hits[i] == 0);
            if (w[i] > 0) CHECK(hits[i] > 0);
            // Rounding each bucket's split to whole steps: at most 1.5 steps per bucket that
            // holds i (its own and those aliased to it).
            CHECK(std::abs(double(table[i].pmf) - w[i] / total) <= 1.5 * double(n + 1) * 0x1.0p-24);
        }
    }
    // A weight far below one step of a bucket still gets one.
    std::vector<gpu::AliasEntry> tiny_alias = build_alias_table({1.0, 1e-20, 0.0, 3.0});
    CHECK(tiny_alias[1].pmf == 0x1.0p-24f);
    CHECK(tiny_alias[2].pmf == 0.0f);
    CHECK(tiny_alias[2].threshold == 0u);
}

TEST_CASE("discrete samplers report their pmf and match the weights (chi2)",
          "[sampling][discrete]") {
    Device& d = device();
    int vector_index = 0;
    for (const std::vector<double>& w : weight_vectors()) {
        ++vector_index;
        double total = std::accumulate(w.begin(), w.end(), 0.0);
        cl_uint n = cl_uint(w.size());
        cl::Buffer cdf = d.buffer(build_cdf(w)), table = d.buffer(build_alias_table(w));
        cl::Buffer out = d.output<cl_uint4>(kSamples), pmf = d.output<float>(n);
        std::vector<float> pmfs[2];
        std::vector<double> frequency[2];
        for (cl_uint method : {0u, 1u}) {
            const char* name = method == 0 ? "CDF" : "alias";
            INFO("weights " << vector_index << ", " << name);
            d.run("discrete_pmfs", n, method, cdf, table, n, pmf);
            pmfs[method] = d.read<float>(pmf, n);
            CHECK(std::accumulate(pmfs[method].begin(), pmfs[method].end(), 0.0) ==
                  Approx(1.0).epsilon(1e-6));
            d.run("sample_discrete", kSamples, method, cdf, table, n, cl_uint(kSamples),
                  cl_uint(50 + vector_index), out);
            std::vector<cl_uint4> s = d.read<cl_uint4>(out, kSamples);
            std::vector<double> observed(n, 0.0), expected(n);
            size_t wrong_pmf = 0, zero_selected = 0, out_of_range = 0;
            for (const cl_uint4& x : s) {
                if (x.s[0] >= n) {
                    ++out_of_range;
                    continue;
                }
                float reported;
                std::memcpy(&reported, &x.s[1], sizeof reported);
                if (reported != pmfs[method][x.s[0]]) ++wrong_pmf;
                if (w[x.s[0]] == 0) ++zero_selected;
                observed[x.s[0]] += 1;
            }
            CHECK(out_of_range == 0);
            CHECK(wrong_pmf == 0);
            CHECK(zero_selected == 0);
            for (cl_uint i = 0; i < n; ++i) {
                // Samples against the pmf the sampler reports (what an estimator divides by).
                expected[i] = kSamples * double(pmfs[method][i]);
                // That pmf is the weights' up to the 2^-24 grid both are built on: two steps
                // for the CDF, 1.5 steps per bucket holding i for the alias table.
                double tolerance = method == 0 ? 0x1.0p-23 : 1.5 * double(n + 1) * 0x1.0p-24;
                CHECK(std::abs(pmfs[method][i] - w[i] / total) <= tolerance);
            }
            Chi2 r = chi2_test(
                "discrete " + std::string(name) + " weights " + std::to_string(vector_index),
                observed, expected);
            CHECK(r.statistic < r.critical);
            frequency[method] = observed;
        }
        // Same distribution: the two pmfs agree within the CDF's rounding.
        for (cl_uint i = 0; i < n; ++i) CHECK(std::abs(pmfs[0][i] - pmfs[1][i]) <= 0x1.0p-22);
    }
}

TEST_CASE("the remapped selection number is uniform within every choice (chi2)",
          "[sampling][discrete]") {
    // A light's triangle and the point on it come from one sample: given the choice, u_remap
    // must be uniform on [0, 1), also for choices of one grid step (the 1e-20 weight).
    Device& d = device();
    constexpr int kBins = 16;
    int vector_index = 0;
    for (const std::vector<double>& w : weight_vectors()) {
        ++vector_index;
        cl_uint n = cl_uint(w.size());
        cl::Buffer cdf = d.buffer(build_cdf(w)), table = d.buffer(build_alias_table(w));
        cl::Buffer out = d.output<cl_uint4>(kSamples);
        for (cl_uint method : {0u, 1u, 2u}) {
            const char* name = method == 0 ? "CDF" : method == 1 ? "alias" : "uniform";
            d.run("sample_discrete", kSamples, method, cdf, table, n, cl_uint(kSamples),
                  cl_uint(90 + vector_index), out);
            std::vector<cl_uint4> s = d.read<cl_uint4>(out, kSamples);
            std::vector<double> observed(size_t(n) * kBins, 0.0), count(n, 0.0);
            size_t outside = 0;
            for (const cl_uint4& x : s) {
                float r;
                std::memcpy(&r, &x.s[2], sizeof r);
                if (x.s[0] >= n || !(r >= 0.0f && r < 1.0f)) {
                    ++outside;
                    continue;
                }
                observed[size_t(x.s[0]) * kBins + size_t(r * kBins)] += 1;
                count[x.s[0]] += 1;
            }
            INFO("weights " << vector_index << ", " << name);
            CHECK(outside == 0);
            // Expected: the choice's count spread evenly over the bins; choices seen too rarely
            // for a χ² cell are pooled by chi2_test's rule.
            std::vector<double> expected(observed.size());
            for (size_t k = 0; k < expected.size(); ++k) expected[k] = count[k / kBins] / kBins;
            Chi2 r =
                chi2_test("remap " + std::string(name) + " weights " + std::to_string(vector_index),
                          observed, expected);
            CHECK(r.statistic < r.critical);
        }
    }
}

// ---- Light tree ---------------------------------------------------------------------------

// Emissive triangles for the light tree's tests: small triangles of random orientation (some
// double-sided, a fifth facing away from the origin), powers spread over 10^4, in a cube or a
// cube; `zero_power` of them have none. n = 0 means the chain case: lights along x at 1.2^i,
// sized in proportion, which a greedy cost peels one by one into a path longer than the limit.
struct TreeLights {
    std::vector<gpu::Light> lights;
    std::vector<double> powers;
};

gpu::float4 g4(const dvec3& v, float w = 0.0f) { return {float(v.x), float(v.y), float(v.z), w}; }
dvec3 d3(const gpu::float4& v) { return dvec3(v.x, v.y, v.z); }

TreeLights tree_lights(int n, uint32_t seed, int zero_power = 0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto sphere = [&] {
        double z = 2 * unit(rng) - 1, phi = 2 * kPi * unit(rng), r = std::sqrt(1 - z * z);
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    TreeLights t;
    const bool chain = n == 0;
    if (chain) n = 120;
    for (int i = 0; i < n; ++i) {
        const double scale = chain ? std::pow(1.2, i) : 1.0;
        dvec3 c = chain ? dvec3(scale, 0, 0)
                        : dvec3(2 * unit(rng) - 1, 2 * unit(rng) - 1, 2 * unit(rng) - 1);
        dvec3 normal = sphere();
        if (unit(rng) < 0.2) normal = -glm::normalize(c + dvec3(1e-9));  // faces away from 0
        dvec3 a = glm::normalize(
            glm::cross(normal, std::abs(normal.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0)));
        dvec3 b = glm::cross(normal, a);
        double size = 0.05 * scale * (0.2 + unit(rng));
        dvec3 p0 = c, p1 = c + size * a, p2 = c + size * b;  // counter-clockwise about normal
        gpu::Light l{};
        bool two_sided = unit(rng) < 0.25;
        l.p0 = g4(p0);
        l.p1 = g4(p1);
        l.area = float(0.5 * size * size);
        l.flags = two_sided ? MATERIAL_DOUBLE_SIDED : 0u;
        l.p2 = g4(p2);
        l.Le = g4(dvec3(1.0));
        t.lights.push_back(l);
        t.powers.push_back(i < zero_power ? 0.0 : std::pow(10.0, 4.0 * unit(rng)));
    }
    return t;
}

// Shading points of the tests: positions in a cube a little larger than the lights', normals
// uniform on the sphere.
void tree_points(size_t count, uint32_t seed, std::vector<cl_float4>& p,
                 std::vector<cl_float4>& n) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (size_t k = 0; k < count; ++k) {
        p.push_back(f4(dvec3(3 * unit(rng) - 1.5, 3 * unit(rng) - 1.5, 3 * unit(rng) - 1.5)));
        double z = 2 * unit(rng) - 1, phi = 2 * kPi * unit(rng), r = std::sqrt(1 - z * z);
        n.push_back(f4(dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    }
}

struct TreeCase {
    int n;
    int zero_power;
};
const std::vector<TreeCase> kTreeCases = {{1, 0}, {2, 0}, {5, 1}, {64, 3}, {1000, 10}, {0, 0}};

TEST_CASE("light tree: every light in one slot, bounds hold what is below them",
          "[sampling][light-tree]") {
    for (const TreeCase& c : kTreeCases) {
        INFO("lights " << c.n);
        TreeLights t = tree_lights(c.n, 7u + uint32_t(c.n), c.zero_power);
        LightTree tree = build_light_tree(t.lights, t.powers);
        const size_t in_tree = t.lights.size() - size_t(c.zero_power);
        REQUIRE(!tree.nodes.empty());
        CHECK(tree.nodes.size() <= std::max<size_t>(1, in_tree - 1));
        std::vector<int> leaf_of(t.lights.size(), 0);
        size_t max_length = 0;
        for (size_t i = 0; i < t.lights.size(); ++i) {
            if (t.powers[i] == 0) {
                CHECK(tree.paths[i].length == 0);
                continue;
            }
            const size_t length = tree.paths[i].length;
            REQUIRE(length >= 1);
            REQUIRE(length <= MCRT_LIGHT_TREE_MAX_DEPTH);
            max_length = std::max(max_length, length);
            // Down the trail: every slot on it bounds the light (sphere, normal cone, power).
            const gpu::Light& l = t.lights[i];
            dvec3 p0 = d3(l.p0), p1 = d3(l.p1), p2 = d3(l.p2);
            dvec3 normal = glm::normalize(glm::cross(p1 - p0, p2 - p0));
            uint32_t node = 0;
            for (size_t d = 0; d < length; ++d) {
                REQUIRE(node < tree.nodes.size());
                const gpu::LightTreeNode& x = tree.nodes[node];
                const int k = int((tree.paths[i].bits >> (2 * d)) & 3u);
                auto at = [k](const gpu::float4& v) { return double((&v.x)[k]); };
                const dvec3 centre(at(x.x), at(x.y), at(x.z));
                for (const dvec3& v : {p0, p1, p2}) CHECK(glm::length(v - centre) <= at(x.radius));
                dvec3 axis(at(x.ax), at(x.ay), at(x.az));
                CHECK(glm::dot(axis, normal) >= at(x.cos_o) - 1e-6);
                CHECK(at(x.sin_o) >= std::sqrt(std::max(0.0, 1 - at(x.cos_o) * at(x.cos_o))));
                CHECK(at(x.cos_e) <= 0.0);
                CHECK(at(x.phi) >= 0.999 * t.powers[i]);
                if ((l.flags & MATERIAL_DOUBLE_SIDED) != 0)
                    CHECK((x.flags & (LIGHT_SLOT_TWO_SIDED << k)) != 0);
                if (d + 1 == length) {
                    CHECK((x.flags & (LIGHT_SLOT_LEAF << k)) != 0);
                    CHECK(x.child[k] == i);
                    leaf_of[i] += 1;
                } else {
                    REQUIRE((x.flags & (LIGHT_SLOT_LEAF << k)) == 0);
                    node = x.child[k];
                }
            }
        }
        for (size_t i = 0; i < t.lights.size(); ++i) CHECK(leaf_of[i] == (t.powers[i] > 0 ? 1 : 0));
        // Every slot: a light, a node or empty (no power); as many light slots as lights.
        size_t light_slots = 0;
        for (const gpu::LightTreeNode& x : tree.nodes)
            for (int k = 0; k < 4; ++k) {
                if ((x.flags & (LIGHT_SLOT_LEAF << k)) != 0) ++light_slots;
                if ((&x.phi.x)[k] == 0.0f) CHECK((&x.cos_e.x)[k] == 1.0f);
            }
        CHECK(light_slots == in_tree);
        // The root's slots hold the power of all.
        const gpu::float4& phi = tree.nodes[0].phi;
        CHECK(double(phi.x) + phi.y + phi.z + phi.w ==
              Approx(std::accumulate(t.powers.begin(), t.powers.end(), 0.0)).epsilon(1e-5));
        if (c.n == 0) CHECK(max_length <= MCRT_LIGHT_TREE_MAX_DEPTH);  // the chain stays within it
        std::printf("light tree of %zu lights: %zu nodes, longest path %zu nodes\n", in_tree,
                    tree.nodes.size(), max_length);
    }
}

TEST_CASE("light tree: the parallel build gives the same tree whatever the number of threads",
          "[sampling][light-tree]") {
    // Enough lights that subtrees are built, and collapsed, on threads of their own (more than
    // kParallelGrain lights and nodes).
    TreeLights t = tree_lights(150000, 23u, 100);
    LightTree one = build_light_tree(t.lights, t.powers, 1);
    for (int threads : {2, 3, 8}) {
        INFO("threads " << threads);
        LightTree many = build_light_tree(t.lights, t.powers, threads);
        REQUIRE(many.nodes.size() == one.nodes.size());
        CHECK(std::memcmp(many.nodes.data(), one.nodes.data(),
                          one.nodes.size() * sizeof(gpu::LightTreeNode)) == 0);
        REQUIRE(many.paths.size() == one.paths.size());
        CHECK(std::memcmp(many.paths.data(), one.paths.data(),
                          one.paths.size() * sizeof(gpu::LightTreePath)) == 0);
    }
}

// The tree's lights and shading points on the device.
struct TreeOnDevice {
    TreeLights t;
    cl_uint n;
    cl::Buffer nodes, paths, p, normal;
    std::vector<cl_float4> points, normals;
    TreeOnDevice(Device& d, const TreeCase& c, size_t point_count)
        : t(tree_lights(c.n, 11u + uint32_t(c.n), c.zero_power)) {
        LightTree tree = build_light_tree(t.lights, t.powers);
        n = cl_uint(t.lights.size());
        tree_points(point_count, 3u + uint32_t(c.n), points, normals);
        nodes = d.buffer(tree.nodes);
        paths = d.buffer(tree.paths);
        p = d.buffer(points);
        normal = d.buffer(normals);
    }
};

TEST_CASE("light tree: pmfs sum to 1 at every point, the sampler reports the twin's pmf",
          "[sampling][light-tree]") {
    // Enumeration: the twin's pmf of every light at a point sums to one (or to zero where no
    // light can reach the point: the sampler then finds none, and the geometry agrees that no
    // light shows an emitting face above the point's horizon), and each sample's pmf is bit
    // for bit the twin's of the light it chose.
    Device& d = device();
    constexpr size_t kPoints = 64, kPerPoint = 4096;
    for (const TreeCase& c : kTreeCases) {
        TreeOnDevice tree(d, c, kPoints);
        INFO("lights " << tree.n);
        cl::Buffer pmf = d.output<float>(tree.n * kPoints);
        d.run("light_tree_pmfs", tree.n * kPoints, tree.nodes, tree.paths, tree.n, cl_uint(kPoints),
              tree.p, tree.normal, pmf);
        std::vector<float> pmfs = d.read<float>(pmf, tree.n * kPoints);
        cl::Buffer out = d.output<cl_uint4>(kPoints * kPerPoint);
        d.run("sample_light_tree_at", kPoints * kPerPoint, tree.nodes, tree.paths, cl_uint(kPoints),
              cl_uint(kPerPoint), 0u, 5u, tree.p, tree.normal, out);
        std::vector<cl_uint4> s = d.read<cl_uint4>(out, kPoints * kPerPoint);
        size_t reachable = 0, wrong_twin = 0, zero_chosen = 0, out_of_range = 0, none_chosen = 0;
        for (size_t k = 0; k < kPoints; ++k) {
            double sum = 0;
            for (size_t i = 0; i < tree.n; ++i) sum += pmfs[k * tree.n + i];
            if (sum != 0) {
                ++reachable;
                CHECK(sum == Approx(1.0).epsilon(1e-5));
            } else {
                const dvec3 p = d3(tree.points[k]), n = d3(tree.normals[k]);
                for (size_t i = 0; i < tree.n; ++i) {
                    const gpu::Light& l = tree.t.lights[i];
                    dvec3 v[3] = {d3(l.p0), d3(l.p1), d3(l.p2)};
                    dvec3 ln = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
                    bool two_sided = (l.flags & MATERIAL_DOUBLE_SIDED) != 0;
                    bool above = false;
                    for (const dvec3& y : v) above = above || glm::dot(n, y - p) > 1e-6;
                    bool facing = two_sided || glm::dot(ln, p - v[0]) > -1e-6;
                    INFO("point " << k << " light " << i);
                    CHECK(!(above && facing && tree.t.powers[i] > 0));
                }
            }
            for (size_t j = k * kPerPoint; j < (k + 1) * kPerPoint; ++j) {
                float reported, twin;
                std::memcpy(&reported, &s[j].s[1], sizeof reported);
                std::memcpy(&twin, &s[j].s[3], sizeof twin);
                if (reported == 0.0f) {
                    none_chosen += sum != 0 ? 1 : 0;
                    continue;
                }
                if (s[j].s[0] >= tree.n) {
                    ++out_of_range;
                    continue;
                }
                if (reported != twin || reported != pmfs[k * tree.n + s[j].s[0]]) ++wrong_twin;
                if (tree.t.powers[s[j].s[0]] == 0) ++zero_chosen;
            }
        }
        CHECK(reachable > kPoints / 4);
        CHECK(none_chosen == 0);
        CHECK(out_of_range == 0);
        CHECK(wrong_twin == 0);
        CHECK(zero_chosen == 0);
    }
}

TEST_CASE(
    "light tree: selection frequencies match the pmf (chi2), stratified u stays stratified, "
    "u_remap is uniform (chi2)",
    "[sampling][light-tree]") {
    Device& d = device();
    constexpr int kBins = 16;
    int tested = 0;
    for (const TreeCase& c : kTreeCases) {
        if (c.n < 2) continue;
        TreeOnDevice tree(d, c, 8);
        cl::Buffer pmf = d.output<float>(tree.n * 8);
        d.run("light_tree_pmfs", tree.n * 8, tree.nodes, tree.paths, tree.n, cl_uint(8), tree.p,
              tree.normal, pmf);
        std::vector<float> pmfs = d.read<float>(pmf, tree.n * 8);
        // The first point that some light reaches.
        size_t k = 0;
        while (k < 8 && std::accumulate(pmfs.begin() + long(k * tree.n),
                                        pmfs.begin() + long((k + 1) * tree.n), 0.0) == 0)
            ++k;
        REQUIRE(k < 8);
        std::vector<cl_float4> one_p{tree.points[k]}, one_n{tree.normals[k]};
        cl::Buffer p1 = d.buffer(one_p), n1 = d.buffer(one_n);
        cl::Buffer out = d.output<cl_uint4>(kSamples);
        const std::string name = "light tree " + std::to_string(tree.n);
        for (cl_uint stratified : {0u, 1u}) {
            d.run("sample_light_tree_at", kSamples, tree.nodes, tree.paths, 1u, cl_uint(kSamples),
                  stratified, 9u, p1, n1, out);
            std::vector<cl_uint4> s = d.read<cl_uint4>(out, kSamples);
            std::vector<double> observed(tree.n, 0.0), expected(tree.n);
            std::vector<double> remap(size_t(tree.n) * kBins, 0.0), remap_expected(remap.size());
            size_t outside = 0;
            for (const cl_uint4& x : s) {
                float r, reported;
                std::memcpy(&r, &x.s[2], sizeof r);
                std::memcpy(&reported, &x.s[1], sizeof reported);
                if (x.s[0] >= tree.n || !(r >= 0.0f && r < 1.0f) || !(reported > 0.0f)) {
                    ++outside;
                    continue;
                }
                observed[x.s[0]] += 1;
                remap[size_t(x.s[0]) * kBins + size_t(r * kBins)] += 1;
            }
            CHECK(outside == 0);
            for (size_t i = 0; i < tree.n; ++i)
                expected[i] = kSamples * double(pmfs[k * tree.n + i]);
            for (size_t b = 0; b < remap.size(); ++b)
                remap_expected[b] = observed[b / kBins] / kBins;
            if (stratified == 0) {
                Chi2 r = chi2_test(name + " frequencies", observed, expected);
                CHECK(r.statistic < r.critical);
                r = chi2_test(name + " remap", remap, remap_expected);
                CHECK(r.statistic < r.critical);
                tested += 2;
            } else {
                // Evenly spaced u: the choice inverts a CDF laid out in tree order, so each
                // light is chosen pmf·N times to within one at each end of its interval (u is
                // read on the 2^-24 grid), plus the pmf's float rounding: far tighter than the
                // ±sqrt(pmf·N) of independent samples.
                double worst = 0;
                for (size_t i = 0; i < tree.n; ++i)
                    worst = std::max(
                        worst, std::abs(observed[i] - expected[i]) / (2.0 + 1e-5 * expected[i]));
                INFO(name << ": worst |count - pmf N| / (2 + 1e-5 pmf N) " << worst);
                CHECK(worst <= 1.0);
            }
        }
    }
    CHECK(tested == 8);
}

// ---- Frames -------------------------------------------------------------------------------

TEST_CASE("frame_from_normal is orthonormal, right-handed, and round-trips", "[sampling]") {
    std::vector<dvec3> normals = {{0, 0, 1},        {0, 0, -1},       {1, 0, 0},    {0, 1, 0},
                                  {-1, 0, 0},       {0, -1, 0},       {1e-8, 0, 1}, {0, 1e-8, -1},
                                  {1e-4, 1e-4, -1}, {1e-4, -1e-4, 1}, {1, 1, 1e-7}, {1, 0, -1e-7}};
    std::mt19937 rng(61);
    std::normal_distribution<double> g;
    while (normals.size() < 10000) normals.emplace_back(g(rng), g(rng), g(rng));
    std::vector<cl_float4> n, v;
    for (const dvec3& x : normals) {
        n.push_back(f4(glm::normalize(x)));
        v.push_back(f4(dvec3(g(rng), g(rng), g(rng))));
    }
    n[n.size() - 1] = {{1.0f, 0.0f, -0.0f, 0.0f}};  // negative zero z
    Device& d = device();
    cl::Buffer nb = d.buffer(n), vb = d.buffer(v), out = d.output<cl_float4>(4 * n.size());
    d.run("frames", n.size(), cl_uint(n.size()), nb, vb, out);
    std::vector<cl_float4> f = d.read<cl_float4>(out, 4 * n.size());
    size_t bad = 0;
    for (size_t k = 0; k < n.size(); ++k) {
        dvec3 t = d3(f[4 * k]), b = d3(f[4 * k + 1]), z = d3(f[4 * k + 2]), back = d3(f[4 * k + 3]);
        dvec3 nk = d3(n[k]), vk = d3(v[k]);
        const double eps = 1e-5;
        bool ok = std::abs(glm::length(t) - 1) < eps && std::abs(glm::length(b) - 1) < eps &&
                  std::abs(glm::dot(t, b)) < eps && std::abs(glm::dot(t, nk)) < eps &&
                  std::abs(glm::dot(b, nk)) < eps && glm::length(glm::cross(t, b) - nk) < eps &&
                  z == nk && glm::length(back - vk) < eps * (1 + glm::length(vk));
        if (!ok) {
            ++bad;
            UNSCOPED_INFO("normal " << nk.x << " " << nk.y << " " << nk.z);
        }
    }
    CHECK(bad == 0);
}
