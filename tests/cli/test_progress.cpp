// The progress bar's fraction: finished launches move it, the image's whole chunk rows floor it.
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <string>
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

namespace {
// What `bar` wrote into `file`.
std::string written(std::FILE* file) {
    std::fflush(file);
    std::rewind(file);
    std::string text;
    for (int c; (c = std::fgetc(file)) != EOF;) text += char(c);
    return text;
}
}  // namespace

TEST_CASE(
    "without a terminal, progress is a line at the start, then per tenth, at most one a second",
    "[cli][progress]") {
    const uint64_t pixels = 1000;
    std::FILE* log = std::tmpfile();
    REQUIRE(log);
    const auto t0 = std::chrono::steady_clock::now();
    auto at = [&](double seconds) {
        return t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(seconds));
    };
    {
        ProgressBar bar(true, pixels, false, log);
        bar.update(0, 100, {}, at(0.0));                             // the start: a line
        bar.update(0, 100, {device_with(5 * pixels)}, at(1.5));      // 5%: no tenth yet
        bar.update(0, 100, {device_with(12 * pixels)}, at(1.6));     // 12%: a line
        bar.update(16, 100, {device_with(25 * pixels)}, at(2.0));    // 25%: 0.4 s later, none
        bar.update(16, 100, {device_with(31 * pixels)}, at(2.6));    // 31%: a line
        bar.update(32, 100, {device_with(39 * pixels)}, at(5.0));    // 39%: the same tenth
        bar.update(96, 100, {device_with(100 * pixels)}, at(6.0));   // all launched: 90%
        bar.update(100, 100, {device_with(100 * pixels)}, at(6.1));  // the image whole
        bar.update(100, 100, {device_with(100 * pixels)}, at(6.2));  // once only
    }
    const std::string text = written(log);
    std::fclose(log);
    INFO(text);
    CHECK(text.find('\r') == std::string::npos);
    size_t lines = 0;
    for (char c : text) lines += c == '\n';
    CHECK(lines == 5);
    CHECK(text.find("  0% 0/100 spp") != std::string::npos);
    CHECK(text.find(" 5%") == std::string::npos);
    CHECK(text.find(" 12% 0/100 spp") != std::string::npos);
    CHECK(text.find(" 31% 16/100 spp") != std::string::npos);
    CHECK(text.find(" 96/100 spp") != std::string::npos);
    CHECK(text.find("100% 100/100 spp") != std::string::npos);
    CHECK(text.find(" 25%") == std::string::npos);
    CHECK(text.back() == '\n');
}

TEST_CASE("on a terminal, progress is one line redrawn in place", "[cli][progress]") {
    std::FILE* log = std::tmpfile();
    REQUIRE(log);
    const auto t0 = std::chrono::steady_clock::now();
    {
        ProgressBar bar(true, 1000, true, log);
        bar.update(0, 100, {device_with(12 * 1000)}, t0);
        bar.update(16, 100, {device_with(25 * 1000)}, t0 + std::chrono::milliseconds(200));
        bar.update(100, 100, {device_with(100 * 1000)}, t0 + std::chrono::milliseconds(400));
    }
    const std::string text = written(log);
    std::fclose(log);
    INFO(text);
    size_t returns = 0, lines = 0;
    for (char c : text) returns += c == '\r', lines += c == '\n';
    CHECK(returns == 3);
    CHECK(lines == 1);  // the finish
    CHECK(text.back() == '\n');
}
