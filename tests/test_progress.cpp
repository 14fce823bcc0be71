// The progress bar's fraction: finished launches move it, the image's whole chunk rows floor it.
#include <catch2/catch.hpp>
#include <vector>

#include "cli/progress.h"

using namespace mcrt;

namespace {
DeviceReport device_with(uint64_t samples) {
    DeviceReport d;
    d.samples = samples;
    return d;
}
}  // namespace

TEST_CASE("progress counts finished launches, not only committed chunk rows", "[cli][progress]") {
    const uint64_t pixels = 1000;
    // 64 spp asked; the image holds 16 (one chunk row), the devices have finished 40 spp' worth.
    const std::vector<DeviceReport> devices = {device_with(30 * pixels), device_with(10 * pixels)};
    CHECK(progress_fraction(16, 64, pixels, devices) == Approx(40.0 / 64.0));
    // Nothing reported yet: what the image holds.
    CHECK(progress_fraction(16, 64, pixels, {}) == Approx(16.0 / 64.0));
    // Reports behind the image (a device retired after its rows were committed): the image.
    CHECK(progress_fraction(32, 64, pixels, {device_with(8 * pixels)}) == Approx(0.5));
    // Never above 1, and an empty render is done.
    CHECK(progress_fraction(64, 64, pixels, {device_with(100 * pixels)}) == 1.0);
    CHECK(progress_fraction(0, 0, pixels, {}) == 1.0);
}
