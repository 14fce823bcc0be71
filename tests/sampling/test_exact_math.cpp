// kernels/core/exact_math.cl on every OpenCL device (entry points in
// tests/kernels/exact_math_test.cl): max ulp error of sinpi, cospi, atan2 and hypot against long
// double references over dense grids, random floats and edge cases; exact values at the special
// points; symmetry. Bit for bit the functions must not depend on the device or its optimiser: each
// device's results equal those of the same device built with -cl-opt-disable, and those of the same
// source compiled for the host by the C++ compiler (the host twin below). Under scripts/with-intel
// both PoCL and Intel's CPU runtime are checked.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <random>

#include "cl/cl_error.h"
#include "cl/program.h"

// ---- Host twin --------------------------------------------------------------------------------

// The OpenCL C built-ins exact_math.cl uses, as host C++ on IEEE floats; this file is compiled
// with -ffp-contract=off (tests/CMakeLists.txt), as the kernel's FP_CONTRACT OFF asks.
namespace host_twin {
using std::copysign;
using std::fabs;
using std::fma;
using std::rint;
using std::signbit;
using std::sqrt;
struct float3 {
    float x, y, z;
};
inline float3 operator+(float3 a, float3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline float3 operator-(float3 a, float3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline float3 operator*(float3 a, float t) { return {a.x * t, a.y * t, a.z * t}; }
#include "exact_math.cl"
}  // namespace host_twin

using namespace mcrt;

namespace {

const long double kPiL = 3.141592653589793238462643383279502884L;

float bits_to_float(uint32_t u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}

uint32_t float_bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// The same bits, or both NaN (a NaN's payload is not specified).
bool same(float a, float b) {
    return float_bits(a) == float_bits(b) || (std::isnan(a) && std::isnan(b));
}

// |y − ref| in units of the float spacing at ref (2^-149 below 2^-126). A reference that
// rounds to ±∞ wants y = ±∞; NaN wants NaN.
double ulp_error(float y, long double ref) {
    constexpr double kWrong = 1e30;
    if (std::isnan(ref) || std::isnan(y)) return std::isnan(ref) && std::isnan(y) ? 0 : kWrong;
    const long double overflow = ldexpl(1.0L, 128) - ldexpl(1.0L, 103);  // rounds to ∞ from here
    if (fabsl(ref) >= overflow) return std::isinf(y) && (y < 0) == (ref < 0) ? 0 : kWrong;
    if (std::isinf(y)) return kWrong;
    int e = ref == 0 ? -126 : std::max(ilogbl(ref), -126);
    return double(fabsl((long double)y - ref) / ldexpl(1.0L, e - 23));
}

struct MaxError {
    double ulp = 0;
    float at = 0, at2 = 0;
    void add(double e, float x, float x2 = 0) {
        if (e > ulp) ulp = e, at = x, at2 = x2;
    }
};

// ---- Devices ----------------------------------------------------------------------------------

struct Program {
    std::shared_ptr<DeviceContext> device;
    cl::Program program;

    template <typename T>
    cl::Buffer input(const std::vector<T>& v) {
        cl_int status;
        cl::Buffer b(device->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                     const_cast<T*>(v.data()), &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        return b;
    }

    // Runs `entry`(count, inputs..., out) over count work-items; returns out's count·per_item.
    template <typename Out, typename... Bufs>
    std::vector<Out> run(const char* entry, size_t count, size_t per_item, const Bufs&... in) {
        cl_int status;
        cl::Buffer out(device->context, CL_MEM_WRITE_ONLY, count * per_item * sizeof(Out), nullptr,
                       &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        cl::Kernel k = make_kernel(program, entry);
        cl_uint index = 0;
        CL_CHECK(k.setArg(index++, cl_uint(count)));
        auto set = [&](const cl::Buffer& b) { CL_CHECK(k.setArg(index++, b)); };
        (set(in), ...);
        CL_CHECK(k.setArg(index++, out));
        CL_CHECK(device->queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(count)));
        std::vector<Out> result(count * per_item);
        CL_CHECK(device->queue.enqueueReadBuffer(out, CL_TRUE, 0, result.size() * sizeof(Out),
                                                 result.data()));
        return result;
    }
};

// Each device that keeps denormals, built as the renderer builds (device_program_options:
// -cl-fp32-correctly-rounded-divide-sqrt where the device offers it) and with -cl-opt-disable.
struct TestDevice {
    std::string name;
    Program optimised, unoptimised;
};

std::vector<TestDevice>& devices() {
    static std::vector<TestDevice> list = [] {
        std::vector<TestDevice> out;
        for (const DeviceInfo& info : enumerate_devices([](const std::string& w) { WARN(w); })) {
            const std::string name = info.platform_name + " / " + info.name;
            if (!(info.single_fp_config & CL_FP_DENORM)) {
                WARN("skipped (flushes denormals): " << name);
                continue;
            }
            if (!info.ieee_basic_operations())
                WARN("does not promise correctly rounded division and sqrt: " << name);
            auto device = std::make_shared<DeviceContext>(info);
            const std::string source = kernel_source("exact_math_test.cl");
            const std::string options = "-cl-std=CL1.2" + device_program_options(info);
            auto build = [&](const std::string& o) {
                return Program{device, build_program(device->context, info.device, source, o)};
            };
            out.push_back({name, build(options), build(options + " -cl-opt-disable")});
        }
        return out;
    }();
    REQUIRE(!list.empty());
    return list;
}

// Checks that two runs of a function on the same inputs agree bit for bit; counts mismatches.
template <typename V>
size_t mismatches(const std::vector<V>& a, const std::vector<V>& b, const char* what) {
    REQUIRE(a.size() == b.size());
    size_t n = 0;
    const size_t floats = sizeof(V) / sizeof(float);
    for (size_t i = 0; i < a.size(); ++i) {
        const float* x = reinterpret_cast<const float*>(&a[i]);
        const float* y = reinterpret_cast<const float*>(&b[i]);
        for (size_t j = 0; j < floats; ++j)
            if (!same(x[j], y[j])) {
                if (n++ < 5)
                    UNSCOPED_INFO(what << " differs at " << i << "." << j << ": " << x[j] << " vs "
                                       << y[j]);
            }
    }
    return n;
}

// The outputs of one-input entry point `kernel` over `inputs` on the optimised build, checked
// bit for bit against the -cl-opt-disable build of the same source.
template <typename Out, typename In>
std::vector<Out> run_both_builds(TestDevice& d, const char* kernel, const std::vector<In>& inputs) {
    cl::Buffer in = d.optimised.input(inputs);
    std::vector<Out> v = d.optimised.run<Out>(kernel, inputs.size(), 1, in);
    cl::Buffer in2 = d.unoptimised.input(inputs);
    CHECK(mismatches(v, d.unoptimised.run<Out>(kernel, inputs.size(), 1, in2), "-cl-opt-disable") ==
          0);
    return v;
}

// ---- Inputs -----------------------------------------------------------------------------------

// A random finite float: sign, exponent in [lo, hi], full mantissa.
float random_float(std::mt19937& rng, int lo, int hi) {
    uint32_t mantissa = rng() & 0x7fffffu, sign = rng() & 0x80000000u;
    int e = lo + int(rng() % uint32_t(hi - lo + 1));
    return e < -126 ? bits_to_float(sign | mantissa)  // denormal
                    : bits_to_float(sign | uint32_t(e + 127) << 23 | mantissa);
}

// A random finite float bit pattern: every exponent, denormals included.
float random_finite(std::mt19937& rng) {
    for (;;) {
        float f = bits_to_float(rng());
        if (std::isfinite(f)) return f;
    }
}

const float kMinDenormal = 0x1p-149f;

// sin(πx) and cos(πx) in long double, exactly 0 and ±1 where they are: x = n/2 + f exactly,
// |f| ≤ 1/4, and the quadrant n mod 4 picks ±sin(πf) or ±cos(πf).
long double sinpi_ref(float x, bool cosine) {
    long double n = rintl(2.0L * x), f = (long double)x - n / 2.0L;
    int quadrant = int(fmodl(fabsl(n), 4.0L));
    if (n < 0) quadrant = (4 - quadrant) % 4;
    long double s = sinl(kPiL * f), c = cosl(kPiL * f);
    if (cosine) return quadrant == 0 ? c : quadrant == 1 ? -s : quadrant == 2 ? -c : s;
    return quadrant == 0 ? s : quadrant == 1 ? c : quadrant == 2 ? -s : -c;
}

// ---- sin(πx), cos(πx) -------------------------------------------------------------------------

constexpr int kGridStepLog2 = 15;  // grid x = i·2^-15 over [−4, 4)
constexpr int kGridPoints = 8 << kGridStepLog2;

std::vector<float> sinpi_inputs() {
    std::vector<float> x;
    for (int i = 0; i < kGridPoints; ++i)
        x.push_back(std::ldexp(float(i - kGridPoints / 2), -kGridStepLog2));
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> turns(0.0f, 2.0f);
    for (int i = 0; i < 262144; ++i) x.push_back(turns(rng));
    for (int i = 0; i < 131072; ++i) x.push_back(random_float(rng, -40, 1));
    for (int i = 0; i < 65536; ++i) x.push_back(random_float(rng, -149, 30));
    for (int i = 0; i < 65536; ++i) x.push_back(random_finite(rng));
    // Integers, half-integers and quarters up to where floats are all even integers, and next
    // to them; tiny, denormal and huge values.
    for (float n :
         {0.0f, 1.0f, 2.0f, 3.0f, 7.0f, 100.0f, 1001.0f, 0x1p22f, 0x1p23f - 1, 0x1p23f, 0x1p23f + 1,
          0x1p23f + 3, 0x1p24f - 2, 0x1p24f, 0x1p24f + 2, 0x1p25f, 1e30f, FLT_MAX}) {
        for (float d : {0.0f, 0.25f, 0.5f, 0.75f}) {
            float v = n + d;
            x.insert(x.end(), {v, std::nextafter(v, 0.0f), std::nextafter(v, FLT_MAX)});
        }
    }
    for (float v : {kMinDenormal, 0x1p-140f, 0x1.fffffep-127f, FLT_MIN, 1e-30f, 1e-10f, 0x1p-24f,
                    1.0f / 6.0f, 1.0f / 3.0f})
        x.push_back(v);
    x.erase(std::remove_if(x.begin() + kGridPoints, x.end(), [](float v) { return v < 0; }),
            x.end());  // random negatives are covered by the mirror below
    const size_t half = x.size();
    for (size_t i = 0; i < half; ++i) x.push_back(-x[i]);
    return x;
}

TEST_CASE(
    "exact_sinpi, exact_cospi: within 1 ulp, exact at integers and half-integers, odd, "
    "even and 2-periodic bit for bit, the same bits as the host twin and -cl-opt-disable",
    "[exact-math]") {
    const std::vector<float> x = sinpi_inputs();
    const size_t half = x.size() / 2;
    for (TestDevice& d : devices()) {
        INFO(d.name);
        auto v = run_both_builds<cl_float4>(d, "sincospi_values", x);

        MaxError sin_error, cos_error;
        size_t twin = 0, special = 0, asymmetric = 0, aperiodic = 0, sincos = 0;
        for (size_t i = 0; i < x.size(); ++i) {
            const float s = v[i].s[0], c = v[i].s[1];
            sin_error.add(ulp_error(s, sinpi_ref(x[i], false)), x[i]);
            cos_error.add(ulp_error(c, sinpi_ref(x[i], true)), x[i]);
            float host_c;
            const float host_s = host_twin::exact_sincospi(x[i], &host_c);
            twin += !same(s, host_s) || !same(c, host_c) ||
                    !same(s, host_twin::exact_sinpi(x[i])) ||
                    !same(c, host_twin::exact_cospi(x[i]));
            sincos += !same(s, v[i].s[2]) || !same(c, v[i].s[3]);
            // sin(π·±n) = ±0, cos(πn) = (−1)^n; sin(π(n + 1/2)) = (−1)^n, cos(π(n + 1/2)) = +0.
            const float ax = std::fabs(x[i]);
            if (ax == std::floor(ax)) {
                const bool odd = ax < 0x1p24f && std::fmod(ax, 2.0f) == 1.0f;
                special += !same(s, std::copysign(0.0f, x[i])) || c != (odd ? -1.0f : 1.0f);
            } else if (ax - std::floor(ax) == 0.5f) {
                const bool odd = std::fmod(std::floor(ax), 2.0f) == 1.0f;
                special += s != (x[i] < 0 ? -1.0f : 1.0f) * (odd ? -1.0f : 1.0f) || !same(c, 0.0f);
            }
            if (i < half) asymmetric += !same(v[i + half].s[0], -s) || !same(v[i + half].s[1], c);
            if (i + (2 << kGridStepLog2) < size_t(kGridPoints))  // ±0 apart (sin(π·±n) = ±0)
                aperiodic +=
                    v[i + (2 << kGridStepLog2)].s[0] != s || v[i + (2 << kGridStepLog2)].s[1] != c;
        }
        std::printf(
            "%s: exact_sinpi max %.3f ulp (x = %a), exact_cospi max %.3f ulp (x = %a), "
            "%zu points\n",
            d.name.c_str(), sin_error.ulp, sin_error.at, cos_error.ulp, cos_error.at, x.size());
        CHECK(sin_error.ulp < 1.0);
        CHECK(cos_error.ulp < 1.0);
        CHECK(twin == 0);
        CHECK(sincos == 0);
        CHECK(special == 0);
        CHECK(asymmetric == 0);
        CHECK(aperiodic == 0);

        // ±∞ and NaN give NaN.
        std::vector<float> bad = {INFINITY, -INFINITY, NAN};
        cl::Buffer bad_in = d.optimised.input(bad);
        for (const cl_float4& r :
             d.optimised.run<cl_float4>("sincospi_values", bad.size(), 1, bad_in))
            CHECK((std::isnan(r.s[0]) && std::isnan(r.s[1])));
    }
}

// ---- atan2, hypot -----------------------------------------------------------------------------

// (y, x) pairs: a dense sweep of angles, random pairs over wide and full exponent ranges, pairs
// near the reduction's ratios 1/2 and 1, and the special values; then each with y negated and
// with y and x swapped (for the symmetry checks).
std::vector<cl_float2> atan2_inputs() {
    std::vector<cl_float2> p;
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int i = 0; i < 262144; ++i) {
        double theta = kPiL * (2.0 * (i + 0.5) / 262144 - 1.0);
        double r = std::ldexp(1.0 + unit(rng), int(rng() % 41) - 20);
        p.push_back({{float(r * std::sin(theta)), float(r * std::cos(theta))}});
    }
    for (int i = 0; i < 131072; ++i)
        p.push_back({{random_float(rng, -40, 40), random_float(rng, -40, 40)}});
    for (int i = 0; i < 32768; ++i)
        p.push_back({{random_float(rng, -149, 127), random_float(rng, -149, 127)}});
    for (int i = 0; i < 32768; ++i) p.push_back({{random_finite(rng), random_finite(rng)}});
    for (int i = 0; i < 32768; ++i) {
        float x = random_float(rng, -60, 60), ratio = (i & 1) ? 1.0f : 0.5f;
        float y = x * ratio;
        for (int k = int(rng() % 8); k > 0; --k) y = std::nextafter(y, (i & 2) ? 0.0f : FLT_MAX);
        p.push_back({{y, x}});
    }
    const float edges[] = {0.0f,    -0.0f,    kMinDenormal, -kMinDenormal, 0x1p-130f,
                           1.0f,    -1.0f,    3.0f,         4.0f,          1e30f,
                           FLT_MAX, -FLT_MAX, 0x1p126f,     INFINITY,      -INFINITY};
    for (float y : edges)
        for (float x : edges) p.push_back({{y, x}});
    const size_t n = p.size();
    for (size_t i = 0; i < n; ++i) p.push_back({{-p[i].s[0], p[i].s[1]}});
    for (size_t i = 0; i < n; ++i) p.push_back({{p[i].s[1], p[i].s[0]}});
    return p;
}

TEST_CASE(
    "exact_atan2 within 1 ulp and exact_hypot within 1.25 ulp, with C99's special "
    "values, odd in y and symmetric bit for bit, the same bits as the host twin and "
    "-cl-opt-disable",
    "[exact-math]") {
    const std::vector<cl_float2> p = atan2_inputs();
    const size_t third = p.size() / 3;
    for (TestDevice& d : devices()) {
        INFO(d.name);
        auto v = run_both_builds<cl_float2>(d, "atan2_hypot_values", p);

        MaxError atan2_error, hypot_error;
        size_t twin = 0, asymmetric = 0, hypot_axis = 0;
        for (size_t i = 0; i < p.size(); ++i) {
            const float y = p[i].s[0], x = p[i].s[1], a = v[i].s[0], h = v[i].s[1];
            atan2_error.add(ulp_error(a, atan2l(y, x)), y, x);
            hypot_error.add(ulp_error(h, hypotl(x, y)), y, x);
            twin +=
                !same(a, host_twin::exact_atan2(y, x)) || !same(h, host_twin::exact_hypot(x, y));
            if (i < third)
                asymmetric += !same(v[i + third].s[0], -a) || !same(v[i + third].s[1], h) ||
                              !same(v[i + 2 * third].s[1], h);
            if (y == 0) hypot_axis += !same(h, std::fabs(x));  // sqrt(RN(x²)) = |x|
        }
        std::printf(
            "%s: exact_atan2 max %.3f ulp (y, x = %a, %a), exact_hypot max %.3f ulp "
            "(%a, %a), %zu pairs\n",
            d.name.c_str(), atan2_error.ulp, atan2_error.at, atan2_error.at2, hypot_error.ulp,
            hypot_error.at, hypot_error.at2, p.size());
        CHECK(atan2_error.ulp < 1.0);
        CHECK(hypot_error.ulp < 1.25);
        CHECK(twin == 0);
        CHECK(asymmetric == 0);
        CHECK(hypot_axis == 0);

        // C99 F.9.1.4 bit for bit; the multiples of π/4 rounded to float.
        const float pi = float(kPiL), pi_2 = float(kPiL / 2), pi_4 = float(kPiL / 4),
                    pi_3_4 = float(3 * kPiL / 4);
        struct Case {
            float y, x, atan2, hypot;
        };
        const std::vector<Case> cases = {
            {0.0f, 0.0f, 0.0f, 0.0f},
            {-0.0f, 0.0f, -0.0f, 0.0f},
            {0.0f, -0.0f, pi, 0.0f},
            {-0.0f, -0.0f, -pi, 0.0f},
            {0.0f, 5.0f, 0.0f, 5.0f},
            {-0.0f, 5.0f, -0.0f, 5.0f},
            {0.0f, -5.0f, pi, 5.0f},
            {-0.0f, -5.0f, -pi, 5.0f},
            {2.0f, 0.0f, pi_2, 2.0f},
            {2.0f, -0.0f, pi_2, 2.0f},
            {-2.0f, 0.0f, -pi_2, 2.0f},
            {-2.0f, -0.0f, -pi_2, 2.0f},
            {1.0f, 1.0f, pi_4, float(sqrtl(2))},
            {-1.0f, -1.0f, -pi_3_4, float(sqrtl(2))},
            {4.0f, 3.0f, float(atan2l(4, 3)), 5.0f},
            {FLT_MAX, FLT_MAX, pi_4, INFINITY},
            {-FLT_MAX, -FLT_MAX, -pi_3_4, INFINITY},
            {kMinDenormal, kMinDenormal, pi_4, kMinDenormal},
            {kMinDenormal, 1.0f, kMinDenormal, 1.0f},
            {1.0f, kMinDenormal, pi_2, 1.0f},
            {INFINITY, INFINITY, pi_4, INFINITY},
            {-INFINITY, -INFINITY, -pi_3_4, INFINITY},
            {INFINITY, 1.0f, pi_2, INFINITY},
            {1.0f, -INFINITY, pi, INFINITY},
        };
        std::vector<cl_float2> cp;
        for (const Case& c : cases) cp.push_back({{c.y, c.x}});
        cl::Buffer cin = d.optimised.input(cp);
        auto cv = d.optimised.run<cl_float2>("atan2_hypot_values", cp.size(), 1, cin);
        for (size_t i = 0; i < cases.size(); ++i) {
            INFO("atan2, hypot of y = " << cases[i].y << ", x = " << cases[i].x << ": "
                                        << cv[i].s[0] << ", " << cv[i].s[1]);
            CHECK(same(cv[i].s[0], cases[i].atan2));
            CHECK(same(cv[i].s[1], cases[i].hypot));
        }
    }
}

// ---- Vectors and the contraction pragma -------------------------------------------------------

TEST_CASE(
    "exact vector functions are the host twin's bits, near their double values; "
    "FP_CONTRACT OFF holds in the code after exact_math.cl",
    "[exact-math]") {
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> coordinate(-10.0f, 10.0f), unit(0.0f, 1.0f);
    std::vector<cl_float4> a, b;
    for (int i = 0; i < 65536; ++i) {
        a.push_back(
            {{coordinate(rng), coordinate(rng), coordinate(rng), (i % 8 == 0) ? 0.0f : unit(rng)}});
        b.push_back({{coordinate(rng), coordinate(rng), coordinate(rng), 0.0f}});
    }
    for (TestDevice& d : devices()) {
        INFO(d.name);
        cl::Buffer ab = d.optimised.input(a), bb = d.optimised.input(b);
        auto v = d.optimised.run<cl_float4>("vector_values", a.size(), 4, ab, bb);
        cl::Buffer ab2 = d.unoptimised.input(a), bb2 = d.unoptimised.input(b);
        CHECK(mismatches(v, d.unoptimised.run<cl_float4>("vector_values", a.size(), 4, ab2, bb2),
                         "-cl-opt-disable") == 0);
        size_t twin = 0, far = 0, mix_start = 0;
        for (size_t i = 0; i < a.size(); ++i) {
            const host_twin::float3 u{a[i].s[0], a[i].s[1], a[i].s[2]},
                w{b[i].s[0], b[i].s[1], b[i].s[2]};
            const float t = a[i].s[3];
            const cl_float4* r = &v[4 * i];
            const host_twin::float3 n = host_twin::exact_normalize3(u),
                                    c = host_twin::exact_cross3(u, w),
                                    m = host_twin::exact_mix3(u, w, t);
            twin += !same(r[0].s[0], host_twin::exact_dot3(u, w)) ||
                    !same(r[0].s[1], host_twin::exact_length3(u)) ||
                    !same(r[0].s[2], host_twin::exact_mix(u.x, w.x, t));
            for (int j = 0; j < 3; ++j)
                twin += !same(r[1].s[j], (&n.x)[j]) || !same(r[2].s[j], (&c.x)[j]) ||
                        !same(r[3].s[j], (&m.x)[j]);
            // Each within a few roundings of the double value.
            const double ux = u.x, uy = u.y, uz = u.z, wx = w.x, wy = w.y, wz = w.z;
            const double dot = ux * wx + uy * wy + uz * wz,
                         scale = std::fabs(ux * wx) + std::fabs(uy * wy) + std::fabs(uz * wz);
            const double len = std::sqrt(ux * ux + uy * uy + uz * uz);
            far += std::fabs(r[0].s[0] - dot) > 0x1p-22 * scale;
            far += std::fabs(r[0].s[1] - len) > 0x1p-22 * len;
            far +=
                std::fabs(std::sqrt(double(r[1].s[0]) * r[1].s[0] + double(r[1].s[1]) * r[1].s[1] +
                                    double(r[1].s[2]) * r[1].s[2]) -
                          1.0) > 0x1p-21;
            const double cross[3] = {uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx};
            const double cross_scale[3] = {std::fabs(uy * wz) + std::fabs(uz * wy),
                                           std::fabs(uz * wx) + std::fabs(ux * wz),
                                           std::fabs(ux * wy) + std::fabs(uy * wx)};
            for (int j = 0; j < 3; ++j)
                far += std::fabs(r[2].s[j] - cross[j]) > 0x1p-22 * cross_scale[j];
            if (t == 0.0f)
                mix_start += !same(r[3].s[0], u.x) || !same(r[3].s[1], u.y) ||
                             !same(r[3].s[2], u.z) || !same(r[0].s[2], u.x);
        }
        CHECK(twin == 0);
        CHECK(far == 0);
        CHECK(mix_start == 0);

        // a·b + c with a = b = 1 + 2^-12, c = −(1 + 2^-11): 0 rounded twice, 2^-24 fused; and
        // random triples against the host's two roundings.
        std::vector<cl_float4> abc = {
            {{1.0f + 0x1p-12f, 1.0f + 0x1p-12f, -(1.0f + 0x1p-11f), 0.0f}}};
        for (int i = 0; i < 4096; ++i)
            abc.push_back({{coordinate(rng), coordinate(rng), coordinate(rng), 0.0f}});
        cl::Buffer in = d.optimised.input(abc);
        auto out = d.optimised.run<float>("contraction_probe", abc.size(), 1, in);
        CHECK(out[0] == 0.0f);
        size_t fused = 0;
        for (size_t i = 0; i < abc.size(); ++i) {
            volatile float product = abc[i].s[0] * abc[i].s[1];
            fused += !same(out[i], product + abc[i].s[2]);
        }
        CHECK(fused == 0);
    }
}

}  // namespace
