// `mcrt integrate`: the course's first experiment, ∫_Ω cosθ dω = π over the hemisphere with the
// uniform, cosine and perturbed Fibonacci estimators, for a list of sample counts N.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "cl/device.h"

namespace mcrt {

// What `mcrt integrate` is asked for; defaults are those of the command line.
struct IntegrateOptions {
    std::vector<std::string> estimators = {"uniform", "cosine", "fibonacci"};
    std::vector<int64_t> n = {1,   2,    5,    10,   20,    50,    100,   200,
                              500, 1000, 2000, 5000, 10000, 20000, 50000, 100000};
    int64_t repeats = 32;
    int64_t seed = 0;
    int64_t device = 0;
    std::string out;  // CSV path; empty: stdout
};

// One CSV row: `estimate` is repeat 0's estimate; `std_error` the standard deviation (R − 1
// denominator) of the R independent estimates, i.e. the standard error of one estimate;
// `rmse` = sqrt(mean over the R repeats of (estimate_r − π)²).
struct IntegrateRow {
    std::string estimator;
    int64_t n = 0;
    double estimate = 0, error = 0, std_error = 0, rmse = 0;
};

// Largest N: beyond 2^24 a float no longer holds every sample index exactly.
constexpr int64_t kIntegrateMaxN = int64_t(1) << 24;

// Runs the estimators on the device, rows in (estimator, n) order as given. Deterministic: a
// pure function of the options (the device aside). Throws InputError for options out of range.
std::vector<IntegrateRow> integrate_cosine_hemisphere(const DeviceContext& device,
                                                      const IntegrateOptions& options);

// "estimator,n,estimate,error,std_error,rmse" and one line per row.
std::string integrate_csv(const std::vector<IntegrateRow>& rows);

// Registers the `integrate` subcommand on app, filling options when it is parsed.
CLI::App* add_integrate_command(CLI::App& app, IntegrateOptions& options);

// Runs the subcommand: CSV to --out (atomically) or stdout. Returns the exit status; throws
// InputError (exit 2) or RuntimeError (exit 1).
int run_integrate(const IntegrateOptions& options);

}  // namespace mcrt
