#include "cl/device.h"

#include "cl/cl_error.h"
#include "cl/no_device.h"
#include "common/test_hooks.h"

namespace mcrt {

std::string DeviceInfo::type_name() const {
    if (type & CL_DEVICE_TYPE_GPU) return "gpu";
    if (type & CL_DEVICE_TYPE_CPU) return "cpu";
    if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
    return "other";
}

bool DeviceInfo::ieee_basic_operations() const {
    return (single_fp_config & CL_FP_DENORM) &&
           (single_fp_config & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT);
}

template <cl_int Name, typename T>
static T device_info(const cl::Device& device) {
    T value{};
    CL_CHECK(device.getInfo(Name, &value));
    return value;
}

std::vector<DeviceInfo> enumerate_devices(const std::function<void(const std::string&)>& warn) {
    check_icd_files();  // the loader would block or crash on them
    std::vector<cl::Platform> platforms;
    cl_int status = cl::Platform::get(&platforms);
    // The ICD loader answers CL_PLATFORM_NOT_FOUND_KHR (-1001) when no platform is installed.
    if (status == -1001 || platforms.empty()) return {};
    CL_CHECK_STATUS(status, "clGetPlatformIDs");

    std::vector<DeviceInfo> devices;
    for (size_t p = 0; p < platforms.size(); ++p) {
        std::string platform_name = "platform " + std::to_string(p);
        platforms[p].getInfo(CL_PLATFORM_NAME, &platform_name);
        std::string platform_vendor;
        platforms[p].getInfo(CL_PLATFORM_VENDOR, &platform_vendor);
        try {
            std::vector<cl::Device> platform_devices;
            status = platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &platform_devices);
            if (status == CL_DEVICE_NOT_FOUND) continue;
            CL_CHECK_STATUS(status, "clGetDeviceIDs");
            for (const cl::Device& d : platform_devices) {
                DeviceInfo info;
                info.index = int(devices.size());
                info.platform = platforms[p];
                info.device = d;
                info.platform_name = platform_name;
                info.platform_vendor = platform_vendor;
                info.name = device_info<CL_DEVICE_NAME, std::string>(d);
                info.vendor = device_info<CL_DEVICE_VENDOR, std::string>(d);
                info.version = device_info<CL_DEVICE_VERSION, std::string>(d);
                info.driver_version = device_info<CL_DRIVER_VERSION, std::string>(d);
                info.type = device_info<CL_DEVICE_TYPE, cl_device_type>(d);
                info.global_memory = device_info<CL_DEVICE_GLOBAL_MEM_SIZE, cl_ulong>(d);
                info.max_allocation = device_info<CL_DEVICE_MAX_MEM_ALLOC_SIZE, cl_ulong>(d);
                info.compute_units = device_info<CL_DEVICE_MAX_COMPUTE_UNITS, cl_uint>(d);
                info.single_fp_config =
                    device_info<CL_DEVICE_SINGLE_FP_CONFIG, cl_device_fp_config>(d);
                info.fp64 = device_info<CL_DEVICE_DOUBLE_FP_CONFIG, cl_device_fp_config>(d) != 0;
                devices.push_back(std::move(info));
            }
        } catch (const ClError& e) {
            warn("skipping OpenCL platform '" + platform_name + "': " + e.what());
        }
    }
    return devices;
}

DeviceContext::DeviceContext(const DeviceInfo& info_) : info(info_) {
    cl_int status = CL_SUCCESS;
    context = cl::Context(info.device, nullptr, nullptr, nullptr, &status);
    if (test_context_failure(info.index)) status = CL_DEVICE_NOT_AVAILABLE;
    CL_CHECK_STATUS(status, "clCreateContext");
    queue = cl::CommandQueue(context, info.device, CL_QUEUE_PROFILING_ENABLE, &status);
    CL_CHECK_STATUS(status, "clCreateCommandQueue");
}

}  // namespace mcrt
