// Host of bench/probes/wg_slab.cl: times both kernels on the first OpenCL device, alternating,
// and prints nanoseconds per ray and node (medians of the rounds). Build and run:
//   g++ -O2 -std=c++17 bench/probes/wg_slab.cpp -o /tmp/wg_slab -lOpenCL
//   /tmp/wg_slab bench/probes/wg_slab.cl [rounds]
#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#include <CL/opencl.hpp>
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <vector>

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << "usage: wg_slab KERNEL.cl [rounds]\n";
        return 2;
    }
    std::ifstream file(argv[1]);
    std::stringstream source;
    source << file.rdbuf();
    int rounds = argc > 2 ? std::max(1, std::atoi(argv[2])) : 7;
    cl::Context context(CL_DEVICE_TYPE_ALL);
    cl::Device device = context.getInfo<CL_CONTEXT_DEVICES>()[0];
    cl::Program program(context, source.str());
    if (program.build() != CL_SUCCESS) {
        std::cerr << program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
        return 1;
    }
    cl::CommandQueue queue(context, device);
    const size_t rays = size_t(1) << 18;
    const cl_uint node_count = 64;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<float> nodes(24 * node_count), org(4 * rays), inv(4 * rays);
    for (float& x : nodes) x = u(rng);
    for (size_t i = 0; i < rays; ++i) {
        for (int a = 0; a < 3; ++a) {
            org[4 * i + a] = 0.01f * u(rng);  // coherent origins, as a pixel's camera rays
            inv[4 * i + a] = 1.0f / (u(rng) + 0.001f);
        }
        org[4 * i + 3] = 1e30f;
    }
    auto buffer = [&](std::vector<float>& v) {
        return cl::Buffer(context, CL_MEM_COPY_HOST_PTR | CL_MEM_READ_ONLY, v.size() * 4, v.data());
    };
    cl::Buffer b_nodes = buffer(nodes), b_org = buffer(org), b_inv = buffer(inv);
    cl::Buffer b_out(context, CL_MEM_WRITE_ONLY, rays * 4);
    const char* names[] = {"slab_group", "slab_barrier", "slab_float4"};
    const int kernels = 3;
    std::vector<double> ns[kernels];
    for (int r = 0; r <= rounds; ++r) {  // r = 0 warms up
        for (int k = 0; k < kernels; ++k) {
            cl::Kernel kernel(program, names[k]);
            kernel.setArg(0, b_nodes);
            kernel.setArg(1, b_org);
            kernel.setArg(2, b_inv);
            kernel.setArg(3, b_out);
            kernel.setArg(4, node_count);
            auto t0 = std::chrono::steady_clock::now();
            queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(rays), cl::NDRange(64));
            queue.finish();
            double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (r > 0) ns[k].push_back(s * 1e9 / (double(rays) * node_count));
        }
    }
    for (int k = 0; k < kernels; ++k) {
        std::sort(ns[k].begin(), ns[k].end());
        std::cout << names[k] << ": " << ns[k][ns[k].size() / 2] << " ns per ray and node (range "
                  << ns[k].front() << "-" << ns[k].back() << ")\n";
    }
}
