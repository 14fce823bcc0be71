#include "cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace mcrt {

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(bool enabled, uint64_t samples_per_spp, bool redraw, std::FILE* out)
    : enabled_(enabled),
      samples_per_spp_(samples_per_spp),
      redraw_(redraw),
      out_(out),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

double progress_fraction(uint32_t done, uint32_t total, uint64_t samples_per_spp,
                         const std::vector<DeviceReport>& devices) {
    if (total == 0) return 1.0;
    const double committed = double(done) / total;
    uint64_t finished = 0;
    for (const DeviceReport& d : devices) finished += d.samples;
    const double all = double(samples_per_spp) * total;
    const double launched = all > 0 ? double(finished) / all : 0.0;
    return std::min(1.0, std::max(committed, launched));
}

void ProgressBar::update(uint32_t done, uint32_t total, const std::vector<DeviceReport>& devices,
                         std::chrono::steady_clock::time_point now) {
    if (!enabled_ || total == 0) return;
    double fraction = progress_fraction(done, total, samples_per_spp_, devices);
    if (!started_ && fraction > 0) started_ = true, first_ = now, first_fraction_ = fraction;
    if (redraw_) {
        if (done < total && drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
    } else {
        // The first report; then a tenth further than the last line, a second after it; the
        // line at 100% when the image is whole.
        const int tenths = done < total ? std::min(9, int(fraction * 10 + 1e-9)) : 10;
        if (tenths <= tenths_written_) return;
        if (done < total && drawn_ && now - last_ < std::chrono::seconds(1)) return;
        tenths_written_ = tenths;
    }
    last_ = now;
    drawn_ = true;
    // Rate and time left from the work done since the first report (none yet: unknown).
    double since = started_ ? std::chrono::duration<double>(now - first_).count() : 0.0;
    double progress = fraction - first_fraction_;
    bool known = started_ && since > 0 && progress > 0;
    double rate = known ? progress * double(total) * samples_per_spp_ / since : 0.0;
    char left[32] = "?";
    if (fraction >= 1.0)
        std::snprintf(left, sizeof left, "0.0");
    else if (known)
        std::snprintf(left, sizeof left, "%.1f", since * (1 - fraction) / progress);
    const int width = 30;
    int filled = int(fraction * width + 0.5);
    char bar[width + 1];
    for (int k = 0; k < width; ++k) bar[k] = k < filled ? '#' : '.';
    bar[width] = '\0';
    std::string shares;
    int ranks = 1;
    for (const DeviceReport& d : devices) ranks = std::max(ranks, d.rank + 1);
    if (ranks > 1) {
        // Across MPI ranks: each rank's share (rN), retired when all its devices are.
        uint64_t all = 0;
        std::vector<uint64_t> samples(size_t(ranks), 0);
        std::vector<int> live(size_t(ranks), 0);
        for (const DeviceReport& d : devices) {
            all += d.samples;
            samples[size_t(d.rank)] += d.samples;
            live[size_t(d.rank)] += d.retired ? 0 : 1;
        }
        for (int r = 0; r < ranks; ++r) {
            char share[48];
            std::snprintf(share, sizeof share, " r%d:%d%%%s", r,
                          all ? int(100.0 * samples[size_t(r)] / all + 0.5) : 0,
                          live[size_t(r)] ? "" : "(retired)");
            shares += share;
        }
    } else if (devices.size() > 1) {
        uint64_t all = 0;
        for (const DeviceReport& d : devices) all += d.samples;
        for (const DeviceReport& d : devices) {
            char share[48];
            std::snprintf(share, sizeof share, " d%d:%d%%%s", d.index,
                          all ? int(100.0 * d.samples / all + 0.5) : 0,
                          d.retired ? "(retired)" : "");
            shares += share;
        }
    }
    std::fprintf(out_, "%s[%s] %3d%% %u/%u spp  %.2f Msamples/s  %s s left%s%s",
                 redraw_ ? "\r" : "", bar, int(fraction * 100 + 0.5), done, total, rate * 1e-6,
                 left, shares.c_str(), redraw_ ? " " : "\n");
    std::fflush(out_);
}

void ProgressBar::finish() {
    if (enabled_ && drawn_ && redraw_) std::fputc('\n', out_);
    drawn_ = false;
}

}  // namespace mcrt
