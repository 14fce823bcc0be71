// One test kernel file built on the first device, with what the kernel suites do with it:
// upload a vector, allocate an output, read it back, and run an entry point with its arguments
// (tests/sampling/test_sampling.cpp, tests/materials/test_materials.cpp).
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "cl/cl_error.h"
#include "cl/program.h"
#include "device_support.h"

namespace mcrt::test {

struct KernelProgram {
    DeviceContext device = first_device();
    cl::Program program;

    // Built as mcrt builds its own programs (cached_program): with the device's arithmetic and
    // workaround options, in a child process where mcrt's would be.
    KernelProgram(const std::string& file, const std::string& options)
        : program(cached_program(device, file, options)) {}

    // A read-write copy of v (one element when v is empty: never a zero-sized buffer).
    template <typename T>
    cl::Buffer buffer(const std::vector<T>& v) {
        cl_int status;
        std::vector<T> copy = v.empty() ? std::vector<T>(1) : v;
        cl::Buffer b(device.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                     copy.size() * sizeof(T), copy.data(), &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        return b;
    }

    template <typename T>
    cl::Buffer output(size_t n) {
        cl_int status;
        cl::Buffer b(device.context, CL_MEM_READ_WRITE, std::max<size_t>(n, 1) * sizeof(T), nullptr,
                     &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        return b;
    }

    template <typename T>
    std::vector<T> read(const cl::Buffer& b, size_t n) {
        std::vector<T> out(n);
        if (n) CL_CHECK(device.queue.enqueueReadBuffer(b, CL_TRUE, 0, n * sizeof(T), out.data()));
        return out;
    }

    // Runs `entry` over `global` work-items (at least one) with these arguments, in order.
    template <typename... Args>
    void run(const char* entry, size_t global, const Args&... args) {
        cl::Kernel k = make_kernel(program, entry);
        cl_uint index = 0;
        auto set = [&](const auto& arg) { CL_CHECK(k.setArg(index++, arg)); };
        (set(args), ...);
        CL_CHECK(device.queue.enqueueNDRangeKernel(k, cl::NullRange,
                                                   cl::NDRange(std::max<size_t>(global, 1))));
        CL_CHECK(device.queue.finish());
    }
};

}  // namespace mcrt::test
