// `mcrt integrate` end to end: ∫_Ω cosθ dω = π by the uniform (GI Compendium eq. 34), cosine
// (eq. 35) and perturbed Fibonacci estimators; the CSV, the convergence rates and bad options.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "process_support.h"

using namespace mcrt::test;

namespace {

constexpr double kPi = 3.14159265358979323846;
const char* kHeader = "estimator,n,estimate,error,std_error,rmse";

struct Row {
    std::string estimator;
    long long n = 0;
    double estimate = 0, error = 0, std_error = 0, rmse = 0;
};

std::vector<std::string> split(const std::string& line, char sep) {
    std::vector<std::string> fields;
    std::string field;
    std::istringstream in(line);
    while (std::getline(in, field, sep)) fields.push_back(field);
    if (!line.empty() && line.back() == sep) fields.push_back("");
    return fields;
}

std::string describe(const std::vector<std::string>& args) {
    std::string text = "mcrt";
    for (const std::string& a : args) text += " " + a;
    return text;
}

ProcessResult run_mcrt(const TempDir& tmp, const std::vector<std::string>& args) {
    ProcessResult r = run_process(MCRT_EXE, args, tmp.path(), 300.0);
    INFO(describe(args) << "\n  exit " << r.exit_code << ", signal " << r.signal
                        << "\n  stderr: " << r.err);
    REQUIRE_FALSE(r.timed_out);
    REQUIRE(r.signal == 0);
    return r;
}

// Runs `mcrt integrate args` (which must succeed) and parses its CSV, checking its shape.
std::vector<Row> integrate(const std::vector<std::string>& args) {
    TempDir tmp("mcrt-integrate");
    std::vector<std::string> full = {"integrate"};
    full.insert(full.end(), args.begin(), args.end());
    ProcessResult r = run_mcrt(tmp, full);
    INFO(describe(full) << "\nstderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    std::istringstream in(r.out);
    std::string line;
    REQUIRE(std::getline(in, line));
    REQUIRE(line == kHeader);
    std::vector<Row> rows;
    while (std::getline(in, line)) {
        std::vector<std::string> f = split(line, ',');
        INFO("line: " << line);
        REQUIRE(f.size() == 6);
        Row row;
        row.estimator = f[0];
        row.n = std::stoll(f[1]);
        row.estimate = std::stod(f[2]);
        row.error = std::stod(f[3]);
        row.std_error = std::stod(f[4]);
        row.rmse = std::stod(f[5]);
        CHECK(std::isfinite(row.estimate));
        CHECK(row.std_error >= 0);
        CHECK(row.rmse >= 0);
        CHECK(row.error == Approx(row.estimate - kPi).margin(1e-12));
        rows.push_back(row);
    }
    return rows;
}

const Row& find_row(const std::vector<Row>& rows, const std::string& estimator, long long n) {
    for (const Row& r : rows)
        if (r.estimator == estimator && r.n == n) return r;
    FAIL("no row " << estimator << "," << n);
    throw std::logic_error("unreachable");
}

// Least-squares slope of log(rmse) against log(n) over the estimator's rows with n in [lo, hi].
double rmse_slope(const std::vector<Row>& rows, const std::string& estimator, long long lo,
                  long long hi) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int count = 0;
    for (const Row& r : rows) {
        if (r.estimator != estimator || r.n < lo || r.n > hi) continue;
        double x = std::log(double(r.n)), y = std::log(r.rmse);
        sx += x, sy += y, sxx += x * x, sxy += x * y, ++count;
    }
    REQUIRE(count >= 2);
    return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

const std::vector<std::string> kDecades = {"--n",
                                           "100,200,500,1000,2000,5000,10000,20000,50000,100000"};

// Exit 2 with exactly one error line, the first line of stderr, and nothing on stdout.
void check_usage_error(const std::vector<std::string>& args) {
    TempDir tmp("mcrt-integrate");
    ProcessResult r = run_mcrt(tmp, args);
    INFO(describe(args) << "\nstdout: " << r.out << "\nstderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(first_line(r.err).rfind("mcrt: error:", 0) == 0);
    CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
    CHECK(r.out.empty());
}

}  // namespace

TEST_CASE("mcrt integrate prints one CSV row per estimator and N, in order", "[integrate]") {
    std::vector<Row> rows = integrate({"--n", "1,7,30", "--repeats", "2"});
    REQUIRE(rows.size() == 9);
    const char* estimators[] = {"uniform", "cosine", "fibonacci"};
    const long long ns[] = {1, 7, 30};
    for (size_t k = 0; k < rows.size(); ++k) {
        CHECK(rows[k].estimator == estimators[k / 3]);
        CHECK(rows[k].n == ns[k % 3]);
    }
    std::vector<Row> defaults = integrate({"--estimators", "fibonacci"});
    REQUIRE(defaults.size() == 16);  // 1, 2, 5, ..., 100000
    CHECK(defaults.front().n == 1);
    CHECK(defaults.back().n == 100000);
}

TEST_CASE("mcrt integrate: the cosine estimator gives pi up to float rounding at every N",
          "[integrate]") {
    // pdf ∝ integrand: every sample's f/pdf is π (eq. 35), so only float rounding is left.
    for (const Row& r : integrate({"--estimators", "cosine"})) {
        INFO("n = " << r.n << ", estimate " << r.estimate);
        CHECK(std::abs(r.error) <= 1e-5 * kPi);
        CHECK(r.rmse <= 1e-5 * kPi);
        CHECK(r.std_error <= 1e-5 * kPi);
    }
}

TEST_CASE("mcrt integrate: the uniform estimator is unbiased and converges like N^-1/2",
          "[integrate]") {
    const int repeats = 64;
    std::vector<std::string> args = kDecades;
    args.insert(args.end(),
                {"--estimators", "uniform", "--repeats", std::to_string(repeats), "--seed", "7"});
    std::vector<Row> rows = integrate(args);

    const Row& r = find_row(rows, "uniform", 10000);
    INFO("N = 10^4: estimate " << r.estimate << ", std_error " << r.std_error);
    CHECK(std::abs(r.error) <= 4.5 * r.std_error);
    // f/pdf = 2π cosθ with cosθ uniform on [0, 1): σ = 2π/√12 per sample. The spread of R
    // estimates is within 30% of σ/√N (its relative standard error is about 1/√(2R) = 9%).
    CHECK(r.std_error == Approx(2 * kPi / std::sqrt(12.0 * 1e4)).epsilon(0.3));

    // log rmse has a standard error of about 1/√(2R) = 0.09 per point; over three decades the
    // fitted slope's is about 0.09/√Σ(ln N − mean)² ≈ 0.015, so ±0.1 is over 6σ.
    double slope = rmse_slope(rows, "uniform", 100, 100000);
    INFO("fitted slope " << slope);
    CHECK(slope >= -0.6);
    CHECK(slope <= -0.4);
}

TEST_CASE("mcrt integrate: the Fibonacci spiral beats uniform sampling by far", "[integrate]") {
    std::vector<std::string> args = kDecades;
    args.insert(args.end(), {"--estimators", "uniform,fibonacci", "--repeats", "64"});
    std::vector<Row> rows = integrate(args);
    const Row& uniform = find_row(rows, "uniform", 10000);
    const Row& fibonacci = find_row(rows, "fibonacci", 10000);
    INFO("rmse at N = 10^4: uniform " << uniform.rmse << ", fibonacci " << fibonacci.rmse);
    CHECK(fibonacci.rmse * 10 <= uniform.rmse);
    CHECK(std::abs(fibonacci.error) <= 4.5 * fibonacci.std_error);  // unbiased
    double slope = rmse_slope(rows, "fibonacci", 100, 100000);
    INFO("fitted slope " << slope);
    CHECK(slope < -0.9);
}

TEST_CASE("mcrt integrate is deterministic and writes --out atomically", "[integrate]") {
    TempDir tmp("mcrt-integrate");
    const std::vector<std::string> args = {"integrate", "--n", "1,1000,30000", "--repeats", "5",
                                           "--seed",    "11"};
    ProcessResult a = run_mcrt(tmp, args), b = run_mcrt(tmp, args);
    REQUIRE(a.exit_code == 0);
    CHECK(a.out == b.out);

    std::vector<std::string> to_file = args;
    std::string csv = tmp / "out.csv";
    to_file.insert(to_file.end(), {"--out", csv});
    ProcessResult c = run_mcrt(tmp, to_file);
    REQUIRE(c.exit_code == 0);
    CHECK(c.out.empty());
    CHECK(read_whole_file(csv) == a.out);

    std::vector<std::string> other_seed = args;
    other_seed.back() = "12";
    ProcessResult d = run_mcrt(tmp, other_seed);
    REQUIRE(d.exit_code == 0);
    CHECK(d.out != a.out);
}

TEST_CASE("mcrt integrate: repeat 0 does not depend on R or on how launches are chunked",
          "[integrate]") {
    // 100 × 10^5 samples take three launches of 2^22, split inside repeats; 2 × 10^5 take one.
    std::vector<Row> few = integrate({"--n", "100000", "--repeats", "2"});
    std::vector<Row> many = integrate({"--n", "100000", "--repeats", "100"});
    REQUIRE(few.size() == many.size());
    for (size_t k = 0; k < few.size(); ++k) {
        INFO(few[k].estimator);
        CHECK(few[k].estimate == many[k].estimate);
    }
}

TEST_CASE("mcrt integrate rejects bad options with exit 2 and one error line", "[integrate]") {
    check_usage_error({"integrate", "--n", "0"});
    check_usage_error({"integrate", "--n", "10,abc"});
    check_usage_error({"integrate", "--n", "16777217"});
    check_usage_error({"integrate", "--repeats", "1"});
    check_usage_error({"integrate", "--repeats", "4097"});
    check_usage_error({"integrate", "--estimators", "nope"});
    check_usage_error({"integrate", "--estimators", "uniform,nope"});
    check_usage_error({"integrate", "--seed", "-1"});
    check_usage_error({"integrate", "--seed", "4294967296"});
    check_usage_error({"integrate", "--device", "100000"});
    check_usage_error({"integrate", "--bogus"});

    TempDir tmp("mcrt-integrate");
    std::string missing = tmp / "no-such-dir/out.csv";
    check_usage_error({"integrate", "--n", "10", "--out", missing});
    CHECK_FALSE(std::filesystem::exists(tmp / "no-such-dir"));
}

TEST_CASE("mcrt integrate: the Fibonacci error is 2pi(1/2 - u0)/N for this integrand",
          "[integrate]") {
    // cosθ does not depend on φ, and z_i = 1 − (i + u0)/N, so (2π/N)·Σ z_i = π + 2π(½ − u0)/N
    // exactly; u depends on (seed, repeat) only, so N·error is the same at every N.
    std::vector<Row> rows = integrate({"--estimators", "fibonacci", "--repeats", "2"});
    const double error_1 = find_row(rows, "fibonacci", 1).error;
    for (const Row& r : rows) {
        INFO("n = " << r.n << ", error " << r.error << ", error at N = 1 over N " << error_1 / r.n);
        CHECK(std::abs(r.error - error_1 / double(r.n)) <= 1e-6);
    }
}
