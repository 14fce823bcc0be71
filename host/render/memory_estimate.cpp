#include "render/memory_estimate.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "common/error.h"

namespace mcrt {

namespace {

uint64_t with_margin(uint64_t bytes) { return bytes + bytes / 10; }

std::string gib(uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f GiB", double(bytes) / double(uint64_t(1) << 30));
    return text;
}

// A number from a one-line cgroup file ("max" or unreadable: 0).
uint64_t read_cgroup_value(const char* path) {
    std::ifstream in(path);
    std::string word;
    if (!(in >> word) || word == "max") return 0;
    return std::strtoull(word.c_str(), nullptr, 10);
}

}  // namespace

uint64_t render_host_bytes(int width, int height, unsigned replicates) {
    // Per pixel: the accumulator's committed and row means (2 × 3 doubles per replicate) and,
    // with one replicate, squared deviations (2 × 3 doubles); the float image and variance (24);
    // PNG bytes (6); 96 for the rest (EXR and result copies).
    const uint64_t accumulator = 2 * 3 * 8 * uint64_t(replicates) + (replicates == 1 ? 48 : 0);
    return with_margin(uint64_t(width) * uint64_t(height) * (96 + 24 + 6 + accumulator));
}

uint64_t bench_host_bytes(int width, int height) {
    // RayBatch 32, hits 16, surface points and shadow rays 48, results and Embree's copies 32.
    return with_margin(uint64_t(width) * uint64_t(height) * 128);
}

uint64_t available_host_bytes() {
    uint64_t available = 0;
    std::ifstream meminfo("/proc/meminfo");
    std::string line;
    while (std::getline(meminfo, line)) {
        if (line.rfind("MemAvailable:", 0) == 0) {
            std::istringstream fields(line.substr(13));
            uint64_t kib = 0;
            if (fields >> kib) available = kib * 1024;
            break;
        }
    }
    const uint64_t limit = read_cgroup_value("/sys/fs/cgroup/memory.max");
    if (limit > 0) {
        const uint64_t used = read_cgroup_value("/sys/fs/cgroup/memory.current");
        const uint64_t left = limit > used ? limit - used : 0;
        if (available == 0 || left < available) available = left;
    }
    return available;
}

void check_host_memory(const std::string& what, uint64_t needed) {
    const uint64_t available = available_host_bytes();
    if (available > 0 && needed > available) {
        throw RuntimeError(what + " needs about " + gib(needed) + " of host memory; " +
                           gib(available) + " is available");
    }
}

}  // namespace mcrt
