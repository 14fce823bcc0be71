// Choosing OpenCL devices from `--device` specs, for every command that runs kernels.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "cl/device.h"

namespace mcrt {

// Devices named by specs (an index from `mcrt devices`, cpu, gpu or all; repeatable), in list
// order without duplicates; the first device when specs is empty. Throws RuntimeError when
// there is no device (or no cpu / gpu one), InputError for a spec that names none.
std::vector<DeviceInfo> select_devices(const std::vector<std::string>& specs,
                                       const std::function<void(const std::string&)>& warn);

// The one device of index `index` (bench, integrate).
DeviceInfo select_device(long long index, const std::function<void(const std::string&)>& warn);

}  // namespace mcrt
