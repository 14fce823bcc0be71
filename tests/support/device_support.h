// The OpenCL device the kernel tests run on: the first one listed (PoCL in CI).
#pragma once

#include <catch2/catch.hpp>

#include "cl/device.h"

namespace mcrt::test {

inline DeviceContext first_device() {
    std::vector<DeviceInfo> devices = enumerate_devices([](const std::string& w) { WARN(w); });
    REQUIRE(!devices.empty());
    return DeviceContext(devices.front());
}

}  // namespace mcrt::test
