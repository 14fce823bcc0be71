// Light tree benchmark: build time, bytes per light and the device's cost per choice of a light,
// against the CDF, alias and uniform selections, for N random small emitters (N = 10^3 .. 10^6
// by default). Prints a Markdown table (docs/BENCHMARKS.md, "Light selection").
//
// Usage: mcrt_light_tree_bench [N ...] [--choices M]   (M choices per method, default 2^22)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <glm/glm.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "cl/cl_error.h"
#include "cl/device.h"
#include "cl/program.h"
#include "lights/discrete.h"
#include "lights/light_tree.h"

using namespace mcrt;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

gpu::float4 g4(const glm::dvec3& v, float w = 0.0f) {
    return {float(v.x), float(v.y), float(v.z), w};
}

// n triangles of edge 0.002-0.01 in the unit cube, random orientation, a quarter double-sided,
// powers spread over 10^4.
void random_lights(size_t n, std::vector<gpu::Light>& lights, std::vector<double>& powers) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (size_t i = 0; i < n; ++i) {
        glm::dvec3 c(unit(rng), unit(rng), unit(rng));
        double z = 2 * unit(rng) - 1, phi = 6.283185307179586 * unit(rng), r = std::sqrt(1 - z * z);
        glm::dvec3 nrm(r * std::cos(phi), r * std::sin(phi), z);
        glm::dvec3 a = glm::normalize(
            glm::cross(nrm, std::abs(nrm.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        glm::dvec3 b = glm::cross(nrm, a);
        double size = 0.002 + 0.008 * unit(rng);
        gpu::Light l{};
        l.p0 = g4(c);
        l.p1 = g4(c + size * a);
        l.area = float(0.5 * size * size);
        l.flags = unit(rng) < 0.25 ? MATERIAL_DOUBLE_SIDED : 0u;
        l.p2 = g4(c + size * b);
        l.Le = g4(glm::dvec3(1.0));
        lights.push_back(l);
        powers.push_back(std::pow(10.0, 4.0 * unit(rng)));
    }
}

template <typename T>
cl::Buffer buffer(const DeviceContext& d, const std::vector<T>& v) {
    std::vector<T> copy = v.empty() ? std::vector<T>(1) : v;
    cl_int status;
    cl::Buffer b(d.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, copy.size() * sizeof(T),
                 copy.data(), &status);
    CL_CHECK_STATUS(status, "clCreateBuffer");
    return b;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<size_t> sizes;
    cl_uint choices = 1u << 22;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--choices" && i + 1 < argc)
            choices = cl_uint(std::strtoul(argv[++i], nullptr, 10));
        else if (std::strtoul(a.c_str(), nullptr, 10) > 0)
            sizes.push_back(std::strtoul(a.c_str(), nullptr, 10));
        else {
            std::fprintf(stderr, "mcrt_light_tree_bench: error: unknown argument %s\n", a.c_str());
            return 2;
        }
    }
    if (sizes.empty()) sizes = {1000, 10000, 100000, 1000000};
    try {
        std::vector<DeviceInfo> devices = enumerate_devices([](const std::string&) {});
        if (devices.empty()) throw RuntimeError("no OpenCL device");
        DeviceContext d(devices.front());
        cl::Program program = build_program(
            d.context, d.info.device, kernel_source("light_select_bench.cl"),
            // rng.cl wants a sampler; the device's options as the renderer's (correct rounding).
            "-cl-std=CL1.2 -D SAMPLER_INDEPENDENT" + device_program_options(d.info));
        cl::Kernel kernel = make_kernel(program, "light_select_bench");
        // Shading points: the cube's points with random normals, 4096 of them.
        std::mt19937 rng(2);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        std::vector<gpu::float4> points, normals;
        for (int k = 0; k < 4096; ++k) {
            points.push_back(g4(glm::dvec3(unit(rng), unit(rng), unit(rng))));
            double z = 2 * unit(rng) - 1, phi = 6.283185307179586 * unit(rng),
                   r = std::sqrt(1 - z * z);
            normals.push_back(g4(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
        }
        cl::Buffer p = buffer(d, points), nrm = buffer(d, normals);
        cl_int status;
        cl::Buffer out(d.context, CL_MEM_WRITE_ONLY, size_t(choices) * sizeof(float), nullptr,
                       &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        std::printf(
            "device: %s; %u choices per method, 4096 shading points in the lights' cube\n\n",
            d.info.name.c_str(), choices);
        std::printf(
            "| lights | tree build (wall s, %u threads) | build (CPU s) | tree nodes | tree "
            "bytes/light | path (max nodes) | ns/choice uniform | CDF | alias | tree |\n"
            "|---|---|---|---|---|---|---|---|---|---|\n",
            std::max(1u, std::thread::hardware_concurrency()));
        for (size_t n : sizes) {
            std::vector<gpu::Light> lights;
            std::vector<double> powers;
            random_lights(n, lights, powers);
            double build = 1e30, build_cpu = 1e30;
            LightTree tree;
            // Wall and processor time of the build on every core, the least of three.
            for (int r = 0; r < 3; ++r) {
                std::clock_t c0 = std::clock();
                Clock::time_point t0 = Clock::now();
                tree = build_light_tree(lights, powers);
                build = std::min(build, seconds_since(t0));
                build_cpu = std::min(build_cpu, double(std::clock() - c0) / CLOCKS_PER_SEC);
            }
            uint32_t depth = 0;
            for (const gpu::LightTreePath& path : tree.paths) depth = std::max(depth, path.length);
            cl::Buffer cdf = buffer(d, build_cdf(powers)),
                       alias = buffer(d, build_alias_table(powers)), nodes = buffer(d, tree.nodes);
            double ns[4];
            for (cl_uint method = 0; method < 4; ++method) {
                cl_uint index = 0;
                auto set = [&](const auto& arg) { CL_CHECK(kernel.setArg(index++, arg)); };
                set(method);
                set(cdf);
                set(alias);
                set(nodes);
                set(cl_uint(n));
                set(cl_uint(points.size()));
                set(p);
                set(nrm);
                set(choices);
                set(cl_uint(7));
                set(out);
                std::vector<double> times;
                for (int r = 0; r < 6; ++r) {  // a warm-up, then the median of five
                    Clock::time_point t0 = Clock::now();
                    CL_CHECK(
                        d.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(choices)));
                    CL_CHECK(d.queue.finish());
                    if (r > 0) times.push_back(seconds_since(t0));
                }
                std::sort(times.begin(), times.end());
                ns[method] = times[times.size() / 2] / choices * 1e9;
            }
            std::printf("| %zu | %.3f | %.3f | %zu | %.0f | %u | %.1f | %.1f | %.1f | %.1f |\n", n,
                        build, build_cpu, tree.nodes.size(),
                        double(tree.nodes.size() * sizeof(gpu::LightTreeNode)) / double(n), depth,
                        ns[2], ns[0], ns[1], ns[3]);
            std::fflush(stdout);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mcrt_light_tree_bench: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
