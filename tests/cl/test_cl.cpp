// The OpenCL host layer: devices, errors, kernel sources, builds, shared struct layouts.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cl/cl_error.h"
#include "cl/device.h"
#include "cl/program.h"
#include "device_support.h"
#include "shared_types.h"

using namespace mcrt;
using mcrt::test::first_device;

namespace {
// A render program's options: one estimator, light selection, sampler and MIS heuristic each
// (the kernels refuse to build without).
std::string default_render_options() {
    return "-D MCRT_ESTIMATE=estimate_light_area -D LIGHT_SELECT_POWER -D SAMPLER_INDEPENDENT "
           "-D MIS_BALANCE";
}
}  // namespace

TEST_CASE("every device is listed with its index and properties", "[cl]") {
    std::vector<DeviceInfo> devices = enumerate_devices([](const std::string& w) { WARN(w); });
    REQUIRE(!devices.empty());
    for (size_t i = 0; i < devices.size(); ++i) {
        CHECK(devices[i].index == int(i));
        CHECK(!devices[i].name.empty());
        CHECK(devices[i].global_memory > 0);
        CHECK(devices[i].max_allocation > 0);
    }
}

TEST_CASE("OpenCL errors name the call, the code and the place", "[cl]") {
    CHECK(cl_error_name(CL_OUT_OF_RESOURCES) == "CL_OUT_OF_RESOURCES");
    CHECK(cl_error_name(CL_INVALID_KERNEL_ARGS) == "CL_INVALID_KERNEL_ARGS");
    CHECK(cl_error_name(-12345) == "CL_UNKNOWN_ERROR(-12345)");
    try {
        CL_CHECK(clFinish(nullptr));
        FAIL("clFinish(nullptr) succeeded");
    } catch (const ClError& e) {
        std::string what = e.what();
        CHECK(what.find("clFinish(nullptr)") != std::string::npos);
        CHECK(what.find("CL_INVALID_COMMAND_QUEUE") != std::string::npos);
        CHECK(what.find("test_cl.cpp:") != std::string::npos);
        CHECK(e.code == CL_INVALID_COMMAND_QUEUE);
    }
}

TEST_CASE("kernel sources expand includes once, with #line markers", "[cl]") {
    std::string src = kernel_source("render.cl");
    CHECK(src.rfind("#line 1 \"render.cl\"", 0) == 0);
    CHECK(src.find("#line 1 \"shared_types.h\"") != std::string::npos);
    CHECK(src.find("#line 1 \"bvh_traverse.cl\"") != std::string::npos);
    // geometry.cl is reached through several includes but expanded once.
    size_t first = src.find("#line 1 \"geometry.cl\"");
    REQUIRE(first != std::string::npos);
    CHECK(src.find("#line 1 \"geometry.cl\"", first + 1) == std::string::npos);
    CHECK(src.find("#include \"") == std::string::npos);
}

TEST_CASE("MCRT_KERNEL_DIR reads kernels from disk instead of the embedded copy", "[cl]") {
    auto dir = std::filesystem::temp_directory_path() / "mcrt_kernel_override_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "a.cl") << "#include \"b.h\"\nkernel void a() {}\n";
    std::ofstream(dir / "b.h") << "#define FROM_DISK 1\n";
    setenv("MCRT_KERNEL_DIR", dir.c_str(), 1);
    std::string src = kernel_source("a.cl");
    CHECK_THROWS_AS(kernel_source("missing.cl"), RuntimeError);
    unsetenv("MCRT_KERNEL_DIR");
    CHECK(src ==
          "#line 1 \"a.cl\"\n#line 1 \"b.h\"\n#define FROM_DISK 1\n#line 2 \"a.cl\"\n"
          "kernel void a() {}\n");
    CHECK_THROWS_AS(kernel_source("a.cl"), RuntimeError);  // not embedded
    std::filesystem::remove_all(dir);
}

TEST_CASE("a failing build raises an error carrying the build log and the right line", "[cl]") {
    DeviceContext device = first_device();
    std::string source =
        "#line 1 \"broken.cl\"\nkernel void k(global float* x) {\n"
        "    x[0] = undefined_name;\n}\n";
    try {
        build_program(device.context, device.info.device, source, "");
        FAIL("the broken kernel built");
    } catch (const RuntimeError& e) {
        std::string what = e.what();
        CHECK(what.find("kernel build failed") != std::string::npos);
        CHECK(what.find("undefined_name") != std::string::npos);
        CHECK(what.find("broken.cl:2") != std::string::npos);
    }
}

TEST_CASE("the device sees every shared struct with the host's size, alignment and offsets",
          "[cl]") {
    using namespace gpu;
    // The host's view, from the same list the device probe walks (MCRT_SHARED_LAYOUT).
    std::vector<cl_uint> want;
    std::vector<std::string> what;
#define HOST_TYPE(T, size, align)                            \
    want.push_back(sizeof(T)), what.push_back("sizeof " #T); \
    want.push_back(alignof(T)), what.push_back("alignof " #T);
#define HOST_FIELD(T, member, offset) \
    want.push_back(offsetof(T, member)), what.push_back("offsetof " #T "." #member);
    MCRT_SHARED_LAYOUT(HOST_TYPE, HOST_FIELD)
#undef HOST_TYPE
#undef HOST_FIELD
    REQUIRE(want.size() > 40);

    DeviceContext device = first_device();
    cl::Program program = cached_program(device, "render.cl", default_render_options());
    cl::Kernel kernel = make_kernel(program, "shared_type_layout");
    cl_int status;
    cl::Buffer layout(device.context, CL_MEM_WRITE_ONLY, want.size() * sizeof(cl_uint), nullptr,
                      &status);
    REQUIRE(status == CL_SUCCESS);
    CL_CHECK(kernel.setArg(0, layout));
    CL_CHECK(device.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1)));
    std::vector<cl_uint> got(want.size());
    CL_CHECK(device.queue.enqueueReadBuffer(layout, CL_TRUE, 0, got.size() * sizeof(cl_uint),
                                            got.data()));
    for (size_t k = 0; k < want.size(); ++k) {
        INFO(what[k] << ": host " << want[k] << ", device " << got[k]);
        CHECK(got[k] == want[k]);
    }
}
