// A progress bar on stderr: fraction done, samples per second, time left.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "render/renderer.h"

namespace mcrt {

// Fraction of the render done: the samples the devices have finished (Σ DeviceReport::samples,
// which moves with every launch) over pixels · total spp, never below what the image holds
// (done of total spp: whole chunk rows of 16 spp) and never above 1.
double progress_fraction(uint32_t done, uint32_t total, uint64_t samples_per_spp,
                         const std::vector<DeviceReport>& devices);

// Whether stderr is a terminal (isatty(3)).
bool stderr_is_terminal();

class ProgressBar {
  public:
    // On a terminal (`redraw`) one line redrawn in place with carriage returns; elsewhere (a log,
    // a pipe) lines of their own: the first when rendering starts, then one at each further
    // tenth of the render, at most one a second, and the last at 100%. Written to `out`.
    ProgressBar(bool enabled, uint64_t samples_per_spp, bool redraw = stderr_is_terminal(),
                std::FILE* out = stderr);
    ~ProgressBar() { finish(); }  // an error message then starts on a line of its own
    // done of total samples per pixel, and each device's share of the samples; redraws at
    // most ten times a second, and at the end.
    void update(uint32_t done, uint32_t total, const std::vector<DeviceReport>& devices) {
        update(done, total, devices, std::chrono::steady_clock::now());
    }
    // The same at a given time (the tests' clock).
    void update(uint32_t done, uint32_t total, const std::vector<DeviceReport>& devices,
                std::chrono::steady_clock::time_point now);
    void finish();

  private:
    bool enabled_;
    uint64_t samples_per_spp_;
    bool redraw_;
    std::FILE* out_;
    int tenths_written_ = -1;  // without redraw: the tenth of the render of the last line written
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_, last_;
    // The first update with work done: rate and time left are measured from it, so that kernel
    // compilation and scene upload before it do not count as slow rendering.
    bool started_ = false;
    std::chrono::steady_clock::time_point first_;
    double first_fraction_ = 0;
};

}  // namespace mcrt
