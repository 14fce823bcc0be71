#include "cli/integrate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cl/cl_error.h"
#include "cl/device_select.h"
#include "cl/program.h"
#include "cli/messages.h"
#include "common/atomic_file.h"
#include "common/error.h"

namespace mcrt {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Work-items per launch: bounds the sample buffer (16 MiB of floats) whatever N × R is.
constexpr uint64_t kSamplesPerLaunch = uint64_t(1) << 22;

const std::vector<std::string> kIntegrateEstimators = {"uniform", "cosine", "fibonacci"};

const char* kColumnsHelp =
    "Integrates cos(theta) over the hemisphere (exact value pi) with each estimator, for each N,\n"
    "R times with independent random numbers (R = --repeats), and prints one CSV row per\n"
    "(estimator, N):\n"
    "  estimator  uniform: pdf 1/(2 pi) (GI Compendium eq. 34);\n"
    "             cosine: pdf cos(theta)/pi (eq. 35), zero variance: pi up to float rounding;\n"
    "             fibonacci: perturbed spherical Fibonacci spiral, z_i = 1 - (i + u.x)/N,\n"
    "             phi_i = 2 pi frac(i (Phi - 1) + u.y), one random u per repeat; the estimate\n"
    "             is (2 pi/N) sum cos(theta_i)\n"
    "  n          the number of samples (directions) N of one estimate\n"
    "  estimate   the estimate of repeat 0, the mean of N values f/pdf\n"
    "  error      estimate - pi\n"
    "  std_error  standard deviation (R - 1 denominator) of the R independent estimates: the\n"
    "             standard error of one estimate, measured the same way for all estimators\n"
    "  rmse       sqrt(mean over the R repeats of (estimate_r - pi)^2)\n"
    "Output is a pure function of the options: random numbers are hashed from\n"
    "(seed, repeat, sample, dimension) (pcg4d), sums are taken in double in sample order.\n";

void check_options(const IntegrateOptions& o) {
    if (o.estimators.empty()) throw InputError("--estimators: expected at least one estimator");
    for (const std::string& e : o.estimators)
        if (std::find(kIntegrateEstimators.begin(), kIntegrateEstimators.end(), e) ==
            kIntegrateEstimators.end())
            throw InputError("--estimators " + e + ": expected uniform, cosine or fibonacci");
    if (o.n.empty()) throw InputError("--n: expected at least one sample count");
    for (int64_t n : o.n)
        if (n < 1 || n > kIntegrateMaxN)
            throw InputError("--n " + std::to_string(n) + ": expected 1 to " +
                             std::to_string(kIntegrateMaxN));
    if (o.repeats < 2 || o.repeats > 4096)
        throw InputError("--repeats " + std::to_string(o.repeats) + ": expected 2 to 4096");
    if (o.seed < 0 || o.seed > int64_t(UINT32_MAX))
        throw InputError("--seed " + std::to_string(o.seed) + ": expected 0 to 4294967295");
    if (o.device < 0)
        throw InputError("--device " + std::to_string(o.device) + ": expected an index");
}

cl::Buffer device_buffer(const DeviceContext& device, size_t bytes) {
    cl_int status = CL_SUCCESS;
    cl::Buffer buffer(device.context, CL_MEM_WRITE_ONLY, bytes, nullptr, &status);
    CL_CHECK_STATUS(status, "clCreateBuffer(integrate samples)");
    return buffer;
}

// The R estimates of one (estimator, N): sample k ∈ [0, N·R) is sample k mod N of repeat k / N,
// added to its repeat's sum in order of k, so chunking does not change the result.
std::vector<double> estimates(const DeviceContext& device, cl::Kernel& kernel, cl::Buffer& samples,
                              uint32_t n, uint32_t repeats, uint32_t seed) {
    const uint64_t total = uint64_t(n) * repeats;
    std::vector<double> sums(repeats, 0.0);
    std::vector<float> values(size_t(std::min(total, kSamplesPerLaunch)));
    CL_CHECK(kernel.setArg(1, cl_uint(n)));
    CL_CHECK(kernel.setArg(2, cl_uint(seed)));
    CL_CHECK(kernel.setArg(3, samples));
    for (uint64_t first = 0; first < total; first += kSamplesPerLaunch) {
        const uint64_t count = std::min(kSamplesPerLaunch, total - first);
        CL_CHECK(kernel.setArg(0, cl_ulong(first)));
        CL_CHECK(device.queue.enqueueNDRangeKernel(kernel, cl::NullRange,
                                                   cl::NDRange(size_t(count)), cl::NullRange));
        CL_CHECK(device.queue.enqueueReadBuffer(samples, CL_TRUE, 0, size_t(count) * sizeof(float),
                                                values.data()));
        for (uint64_t j = 0; j < count; ++j) sums[size_t((first + j) / n)] += double(values[j]);
    }
    for (double& s : sums) s /= double(n);
    return sums;
}

IntegrateRow summarize(const std::string& estimator, int64_t n, const std::vector<double>& e) {
    const double r = double(e.size());
    double mean = 0, squared_error = 0;
    for (double x : e) mean += x, squared_error += (x - kPi) * (x - kPi);
    mean /= r;
    double spread = 0;
    for (double x : e) spread += (x - mean) * (x - mean);
    IntegrateRow row;
    row.estimator = estimator;
    row.n = n;
    row.estimate = e.front();
    row.error = e.front() - kPi;
    row.std_error = std::sqrt(spread / (r - 1));
    row.rmse = std::sqrt(squared_error / r);
    return row;
}

}  // namespace

std::vector<IntegrateRow> integrate_cosine_hemisphere(const DeviceContext& device,
                                                      const IntegrateOptions& o) {
    check_options(o);
    cl::Program program =
        build_program(device.context, device.info.device, kernel_source("integrate.cl"),
                      "-cl-std=CL1.2 -D SAMPLER_INDEPENDENT");
    const uint32_t repeats = uint32_t(o.repeats);
    const int64_t largest = *std::max_element(o.n.begin(), o.n.end());
    cl::Buffer samples = device_buffer(
        device, size_t(std::min(uint64_t(largest) * repeats, kSamplesPerLaunch)) * sizeof(float));

    std::vector<IntegrateRow> rows;
    for (const std::string& estimator : o.estimators) {
        cl::Kernel kernel = make_kernel(program, ("integrate_" + estimator).c_str());
        for (int64_t n : o.n)
            rows.push_back(summarize(
                estimator, n,
                estimates(device, kernel, samples, uint32_t(n), repeats, uint32_t(o.seed))));
    }
    return rows;
}

std::string integrate_csv(const std::vector<IntegrateRow>& rows) {
    std::string text = "estimator,n,estimate,error,std_error,rmse\n";
    char line[256];
    for (const IntegrateRow& r : rows) {
        std::snprintf(line, sizeof line, "%s,%lld,%.17g,%.6e,%.6e,%.6e\n", r.estimator.c_str(),
                      static_cast<long long>(r.n), r.estimate, r.error, r.std_error, r.rmse);
        text += line;
    }
    return text;
}

CLI::App* add_integrate_command(CLI::App& app, IntegrateOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "integrate", "estimate the integral of cos(theta) over the hemisphere (= pi); CSV out");
    cmd->footer(kColumnsHelp);
    cmd->add_option("--estimators", o.estimators, "comma-separated: uniform, cosine, fibonacci")
        ->delimiter(',')
        ->capture_default_str()
        ->check(CLI::IsMember(kIntegrateEstimators));
    cmd->add_option("--n", o.n, "comma-separated sample counts N, 1 to 2^24")
        ->delimiter(',')
        ->capture_default_str()
        ->check(CLI::Range(int64_t(1), kIntegrateMaxN));
    cmd->add_option("--repeats", o.repeats, "independent estimates R per (estimator, N), 2 to 4096")
        ->capture_default_str()
        ->check(CLI::Range(int64_t(2), int64_t(4096)));
    cmd->add_option("--seed", o.seed, "random seed, 0 to 2^32 - 1")
        ->capture_default_str()
        ->check(CLI::Range(int64_t(0), int64_t(UINT32_MAX)));
    cmd->add_option("--device", o.device, "device index from `mcrt devices`")
        ->capture_default_str()
        ->check(CLI::Range(int64_t(0), int64_t(1) << 20));
    cmd->add_option("--out", o.out, "write the CSV to this file (atomically) instead of stdout");
    return cmd;
}

int run_integrate(const IntegrateOptions& o) {
    check_options(o);
    OutputSet outputs;  // checked, its temporary created, before any device work
    outputs.add("--out", o.out);
    outputs.prepare({});
    DeviceContext device(select_device(o.device, print_warning));
    std::string csv = integrate_csv(integrate_cosine_hemisphere(device, o));
    if (o.out.empty()) {
        std::cout << csv << std::flush;
        if (!std::cout) throw RuntimeError("cannot write to stdout");
        return 0;
    }
    std::ofstream out(outputs.temporary(o.out), std::ios::binary | std::ios::trunc);
    out << csv;
    out.close();
    if (!out) throw RuntimeError(o.out + ": cannot write");
    outputs.commit();
    return 0;
}

}  // namespace mcrt
