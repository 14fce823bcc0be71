// OpenCL platforms and devices, and a context and queue per device.
#pragma once

#include <CL/opencl.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mcrt {

struct DeviceInfo {
    int index = 0;  // position in the list `mcrt devices` prints
    cl::Platform platform;
    cl::Device device;
    std::string name, platform_name, platform_vendor, vendor, version, driver_version;
    cl_device_type type = 0;
    cl_ulong global_memory = 0, max_allocation = 0;
    cl_uint compute_units = 0;
    cl_device_fp_config single_fp_config =
        0;              // CL_FP_DENORM, CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT, ...
    bool fp64 = false;  // cl_khr_fp64 (or OpenCL 1.2's double support)

    // Denormals kept, division and sqrt correctly rounded: the basic operations round as
    // IEEE-754 says, which bitwise agreement with other devices needs (docs/DESIGN.md).
    bool ieee_basic_operations() const;

    std::string type_name() const;  // "cpu", "gpu", "accelerator", "other"
};

// Every device of every platform. A platform that fails to list its devices is skipped with a
// warning instead of aborting; no platform at all gives an empty list.
std::vector<DeviceInfo> enumerate_devices(const std::function<void(const std::string&)>& warn);

// A context and an in-order, profiling-enabled queue on one device.
struct DeviceContext {
    explicit DeviceContext(const DeviceInfo& info);
    DeviceInfo info;
    cl::Context context;
    cl::CommandQueue queue;
};

}  // namespace mcrt
