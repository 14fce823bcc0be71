// Environment maps (host/scene/environment_map.h): the mapping, the texel distribution and its pdf
// twin, estimators of a known irradiance, and hostile files, each one InputError naming the file.
#include <OpenEXR/ImfHeader.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "chi2.h"
#include "common/error.h"
#include "image/image.h"
#include "kernel_program.h"
#include "process_support.h"
#include "scene/environment_map.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string scratch(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / "mcrt_test_environment";
    std::filesystem::create_directories(dir);
    return (dir / name).string();
}

// A Radiance file of flat (not run-length) RGBE texels, every texel (m, m, m, e).
std::string write_hdr(const std::string& name, const std::string& size_line, size_t texels,
                      unsigned char m = 128, unsigned char e = 129) {
    const std::string path = scratch(name);
    std::ofstream out(path, std::ios::binary);
    out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" << size_line << "\n";
    for (size_t k = 0; k < texels; ++k) out << m << m << m << e;
    return path;
}

std::string write_map_exr(const std::string& name, int w, int h, float value) {
    Image image(w, h);
    std::fill(image.rgb.begin(), image.rgb.end(), value);
    const std::string path = scratch(name);
    write_exr(path, image);
    return path;
}

void require_refused(const std::string& path, const std::string& says) {
    try {
        load_environment_map(path, 1.0f);
        FAIL("accepted " << path);
    } catch (const InputError& e) {
        const std::string what = e.what();
        INFO(what);
        REQUIRE(what.find(path) != std::string::npos);
        REQUIRE(what.find(says) != std::string::npos);
    }
}

EnvironmentMap band_map(int w, int h, int first_row, int last_row, float band, float rest) {
    EnvironmentMap map{w, h, std::vector<float>(3 * size_t(w) * h, rest)};
    for (int j = first_row; j <= last_row; ++j) {
        for (int k = 0; k < 3 * w; ++k) map.rgb[3 * size_t(j) * w + k] = band;
    }
    return map;
}

}  // namespace

TEST_CASE("environment mapping follows Mitsuba's envmap for +Y up", "[environment]") {
    const auto uv_minus_z = environment_uv({0, 0, -1}, 0);
    CHECK(uv_minus_z[0] == Approx(0.0).margin(1e-12));
    CHECK(uv_minus_z[1] == Approx(0.5));
    CHECK(environment_uv({1, 0, 0}, 0)[0] == Approx(0.25));
    CHECK(environment_uv({0, 0, 1}, 0)[0] == Approx(0.5));
    CHECK(environment_uv({-1, 0, 0}, 0)[0] == Approx(0.75));
    CHECK(environment_uv({0, 1, 0}, 0)[1] == Approx(0.0));
    CHECK(environment_uv({0, -1, 0}, 0)[1] == Approx(1.0));
    // Turned 90° counter-clockwise seen from above, what was at −Z is at −X.
    CHECK(environment_uv({-1, 0, 0}, 90)[0] == Approx(0.0).margin(1e-12));
    const EnvironmentMap map{8, 4, std::vector<float>(96, 1.0f)};
    CHECK(environment_texel(map, {0, 1, 0}, 0)[1] == 0);
    CHECK(environment_texel(map, {0, -1, 0}, 0)[1] == 3);
}

TEST_CASE("texel solid angles cover the sphere", "[environment]") {
    for (int h : {1, 3, 64}) {
        double sum = 0;
        for (int j = 0; j < h; ++j) sum += 7 * texel_solid_angle(7, h, j);
        CHECK(sum == Approx(4 * kPi).epsilon(1e-12));
    }
}

TEST_CASE("environment power: pi r^2 times radiance over the sphere", "[environment]") {
    const auto sky = uniform_environment_map({2.0f, 2.0f, 2.0f});
    CHECK(environment_power(sky, 3.0) == Approx(4 * kPi * kPi * 9 * 2.0).epsilon(1e-12));
    // A band of rows: π r² Σ_rows L_j · 2π (cos θ_j − cos θ_{j+1}).
    const EnvironmentMap band = band_map(8, 4, 1, 1, 10.0f, 0.0f);
    const double omega = 2 * kPi * (std::cos(kPi / 4) - std::cos(kPi / 2));
    CHECK(environment_power(band, 1.0) == Approx(kPi * 10.0 * omega).epsilon(1e-6));
}

TEST_CASE("environment samples follow their pdf: pdf integrates to 1, chi2 over texels",
          "[environment]") {
    EnvironmentMap map = band_map(16, 8, 2, 3, 50.0f, 1.0f);
    map.rgb[3 * (5 * 16 + 3) + 1] = 0.0f;  // one texel dimmer in green only
    for (int k = 0; k < 3; ++k) map.rgb[3 * (6 * 16 + 9) + k] = 0.0f;  // one dark texel
    const double rotate = 33.0;
    const auto dist = build_environment_distribution(map);
    double total = 0;
    for (int j = 0; j < map.height; ++j) {
        for (int i = 0; i < map.width; ++i) {
            const size_t k = size_t(j) * map.width + i;
            total += double(dist.cdf[k + 1]) - double(dist.cdf[k]);
        }
    }
    CHECK(total == 1.0);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const int n = 200000;
    std::vector<double> observed(size_t(map.width) * map.height, 0.0), expected(observed.size());
    for (int s = 0; s < n; ++s) {
        const double u0 = std::floor(uniform(rng) * 16777216.0) / 16777216.0;  // the kernels' grid
        const auto d = sample_environment(dist, u0, uniform(rng), uniform(rng), rotate);
        REQUIRE(std::abs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1.0) < 1e-12);
        const auto texel = environment_texel(map, d, rotate);
        const size_t k = size_t(texel[1]) * map.width + texel[0];
        observed[k] += 1;
        // The pdf twin: p_texel / Ω_texel at the sampled direction.
        const double pmf = double(dist.cdf[k + 1]) - double(dist.cdf[k]);
        REQUIRE(pmf > 0);
        REQUIRE(environment_pdf_w(dist, d, rotate) ==
                Approx(pmf / texel_solid_angle(map.width, map.height, texel[1])).epsilon(1e-12));
    }
    CHECK(observed[size_t(6) * map.width + 9] == 0);
    for (size_t k = 0; k < expected.size(); ++k) {
        expected[k] = n * (double(dist.cdf[k + 1]) - double(dist.cdf[k]));
    }
    const Chi2 chi2 = chi2_test("environment texels", observed, expected, 1e-3);
    CHECK(chi2.statistic < chi2.critical);
}

TEST_CASE("a band of rows lights a floor with the closed-form irradiance", "[environment]") {
    // E = Σ texels L × ∫cosθ dω over the texel = Σ_rows L_j · W · (2π/W)(cos²θ_j − cos²θ_{j+1})/2
    // over rows above the horizon (the floor's normal is +Y).
    const int w = 32, h = 16;
    const EnvironmentMap map = band_map(w, h, 3, 4, 20.0f, 0.5f);
    double exact = 0;
    for (int j = 0; j < h / 2; ++j) {
        const double c0 = std::cos(kPi * j / h), c1 = std::cos(kPi * (j + 1) / h);
        const double radiance = (j >= 3 && j <= 4) ? 20.0 : 0.5;
        exact += radiance * kPi * (c0 * c0 - c1 * c1);
    }
    const auto dist = build_environment_distribution(map);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const int n = 100000;
    // Environment sampling and cosine hemisphere sampling, each mean and standard error.
    double sum_env = 0, sq_env = 0, sum_cos = 0, sq_cos = 0;
    for (int s = 0; s < n; ++s) {
        const auto d = sample_environment(dist, uniform(rng), uniform(rng), uniform(rng), 0.0);
        const auto t = environment_texel(map, d, 0.0);
        const double L = map.rgb[3 * (size_t(t[1]) * w + t[0])];
        const double f = d[1] > 0 ? L * d[1] / environment_pdf_w(dist, d, 0.0) : 0.0;
        sum_env += f;
        sq_env += f * f;
        const double r = std::sqrt(uniform(rng)), phi = 2 * kPi * uniform(rng);
        const std::array<double, 3> c{r * std::cos(phi), std::sqrt(1 - r * r), r * std::sin(phi)};
        const auto tc = environment_texel(map, c, 0.0);
        const double g = map.rgb[3 * (size_t(tc[1]) * w + tc[0])] * kPi;  // L cosθ / (cosθ/π)
        sum_cos += g;
        sq_cos += g * g;
    }
    for (auto [sum, sq] : {std::pair{sum_env, sq_env}, std::pair{sum_cos, sq_cos}}) {
        const double mean = sum / n, se = std::sqrt((sq / n - mean * mean) / (n - 1));
        INFO("mean " << mean << " exact " << exact << " se " << se);
        CHECK(std::abs(mean - exact) < 4 * se + 1e-12);
    }
}

TEST_CASE("a sun map: environment sampling beats cosine sampling 100x at equal samples",
          "[environment]") {
    // A few texels 10^4 times brighter than a dim sky; efficiency = 1/variance at equal samples.
    const int w = 64, h = 32;
    EnvironmentMap map{w, h, std::vector<float>(3 * size_t(w) * h, 0.1f)};
    for (int j = 9; j <= 10; ++j) {
        for (int i = 20; i <= 21; ++i) {
            for (int k = 0; k < 3; ++k) map.rgb[3 * (size_t(j) * w + i) + k] = 1000.0f;
        }
    }
    const auto dist = build_environment_distribution(map);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const int n = 100000;
    double sum_env = 0, sq_env = 0, sum_cos = 0, sq_cos = 0;
    for (int s = 0; s < n; ++s) {
        const auto d = sample_environment(dist, uniform(rng), uniform(rng), uniform(rng), 0.0);
        const auto t = environment_texel(map, d, 0.0);
        const double f = d[1] > 0 ? map.rgb[3 * (size_t(t[1]) * w + t[0])] * d[1] /
                                        environment_pdf_w(dist, d, 0.0)
                                  : 0.0;
        sum_env += f;
        sq_env += f * f;
        const double r = std::sqrt(uniform(rng)), phi = 2 * kPi * uniform(rng);
        const auto tc = environment_texel(
            map, {r * std::cos(phi), std::sqrt(1 - r * r), r * std::sin(phi)}, 0.0);
        const double g = map.rgb[3 * (size_t(tc[1]) * w + tc[0])] * kPi;
        sum_cos += g;
        sq_cos += g * g;
    }
    const double var_env = sq_env / n - (sum_env / n) * (sum_env / n);
    const double var_cos = sq_cos / n - (sum_cos / n) * (sum_cos / n);
    INFO("variance: environment " << var_env << ", cosine " << var_cos);
    CHECK(var_cos / var_env >= 100.0);
}

TEST_CASE("environment map files: EXR and .hdr read, scaled", "[environment]") {
    const auto exr = load_environment_map(write_map_exr("one.exr", 1, 1, 0.25f), 4.0f);
    CHECK(exr.width == 1);
    CHECK(exr.rgb == std::vector<float>{1.0f, 1.0f, 1.0f});
    const auto hdr = load_environment_map(write_hdr("four.hdr", "-Y 2 +X 4", 8), 2.0f);
    CHECK(hdr.width == 4);
    CHECK(hdr.height == 2);
    for (float v : hdr.rgb) CHECK(v == 2.0f);
    const auto sky = uniform_environment_map({0.5f, 1.0f, 2.0f});
    const auto dist = build_environment_distribution(sky);
    CHECK(environment_pdf_w(dist, {0.3, 0.8, std::sqrt(1 - 0.73)}, 12.0) == Approx(1 / (4 * kPi)));
}

TEST_CASE("hostile environment maps: one InputError naming the file", "[environment]") {
    require_refused(write_hdr("truncated.hdr", "-Y 4 +X 4", 9), "truncated");
    require_refused(write_hdr("huge.hdr", "-Y 32768 +X 65536", 1), "65536x32768");
    const std::string exr = write_map_exr("truncated.exr", 64, 64, 1.0f);
    std::filesystem::resize_file(exr, std::filesystem::file_size(exr) / 2);
    require_refused(exr, "cannot read EXR");
    require_refused(write_map_exr("nan.exr", 2, 2, NAN), "finite and non-negative");
    require_refused(write_map_exr("inf.exr", 2, 2, INFINITY), "finite and non-negative");
    require_refused(write_map_exr("negative.exr", 2, 2, -1.0f), "finite and non-negative");
    require_refused(write_map_exr("zero.exr", 2, 2, 0.0f), "every texel");
    require_refused(write_hdr("zero.hdr", "-Y 2 +X 2", 4, 0, 0), "every texel");
    require_refused(scratch("missing.hdr"), "cannot open");
    require_refused(write_map_exr("named.png", 1, 1, 1.0f), ".exr or .hdr");
}

TEST_CASE("make_sky_maps.py writes maps the reader takes, a sun 10^4 times its sky",
          "[environment]") {
    const char* python = "/usr/bin/python3";
    if (!std::filesystem::exists(python)) skip_test(std::string(python) + " not found");
    const std::filesystem::path dir = std::filesystem::path(scratch("sky-maps"));
    std::filesystem::create_directories(dir);
    const ProcessResult run = run_process(
        python, {std::string(MCRT_SOURCE_DIR) + "/scripts/scenes/make_sky_maps.py", dir.string()},
        dir, 60.0);
    if (run.exit_code != 0 && run.err.find("No module named") != std::string::npos) {
        skip_test("python3 lacks numpy");
    }
    REQUIRE(run.exit_code == 0);
    const auto sun = load_environment_map((dir / "sun-sky.hdr").string(), 1.0f);
    CHECK(sun.width == 512);
    CHECK(sun.height == 256);
    const float brightest = *std::max_element(sun.rgb.begin(), sun.rgb.end());
    const float zenith_blue = sun.rgb[2];  // row 0: the zenith's blue
    CHECK(brightest / zenith_blue > 5e3);
    const auto overcast = load_environment_map((dir / "overcast.hdr").string(), 1.0f);
    // CIE overcast: the zenith row (1 + 2cos θ)/3 at θ = π/64, within RGBE's 1/256.
    CHECK(overcast.rgb[0] == Approx((1 + 2 * std::cos(kPi / 64)) / 3).epsilon(1.0 / 128));
}

TEST_CASE("the device twin samples the texels the host does, with the same pdf", "[environment]") {
    KernelProgram d("environment_test.cl", "");
    EnvironmentMap map = band_map(16, 8, 2, 3, 50.0f, 1.0f);
    for (size_t k = 0; k < map.rgb.size(); k += 3) map.rgb[k] += 0.01f * float(k % 7);
    for (int k = 0; k < 3; ++k) map.rgb[3 * (6 * 16 + 9) + k] = 0.0f;  // a dark texel
    const double rotate = 33.0;
    const auto dist = build_environment_distribution(map);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const size_t n = 20000;
    std::vector<cl_float4> u(n);
    for (auto& v : u) {
        v = {{std::floor(uniform(rng) * 16777216.0f) / 16777216.0f, uniform(rng), uniform(rng),
              uniform(rng)}};
    }
    const float a = float(rotate * kPi / 180.0);
    cl::Buffer out = d.output<cl_float4>(n), check = d.output<cl_float4>(n);
    d.run("environment_samples", n, d.buffer(map.rgb), d.buffer(dist.cdf), cl_uint(map.width),
          cl_uint(map.height), std::cos(a), std::sin(a), cl_uint(n), d.buffer(u), out, check);
    const auto samples = d.read<cl_float4>(out, n), checks = d.read<cl_float4>(check, n);
    size_t on_edge = 0;
    for (size_t s = 0; s < n; ++s) {
        const auto host = sample_environment(dist, u[s].s[0], u[s].s[2], u[s].s[3], rotate);
        const auto texel = environment_texel(map, host, rotate);
        const size_t k = size_t(texel[1]) * map.width + texel[0];
        INFO("sample " << s);
        REQUIRE(size_t(checks[s].s[2]) == k);
        for (int c = 0; c < 3; ++c) REQUIRE(samples[s].s[c] == Approx(host[c]).margin(1e-5));
        REQUIRE(samples[s].s[3] == Approx(environment_pdf_w(dist, host, rotate)).epsilon(1e-5));
        // The twin at the sampled direction; a direction on a texel's edge may round into its
        // neighbour, which float atan2/acos cannot avoid.
        if (size_t(checks[s].s[1]) != k) {
            ++on_edge;
            continue;
        }
        REQUIRE(checks[s].s[0] == Approx(samples[s].s[3]).epsilon(1e-5));
        REQUIRE(checks[s].s[3] == map.rgb[3 * k]);
    }
    INFO("directions read back into a neighbouring texel: " << on_edge);
    CHECK(on_edge <= n / 1000);
}
