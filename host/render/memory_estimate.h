// Host memory a render or bench needs, estimated before anything large is allocated, against
// what the machine (and its cgroup) has available (ROBUSTNESS.md "Images too large").
#pragma once

#include <cstdint>
#include <string>

namespace mcrt {

// Bytes a render holds on the host: per pixel the accumulator's double means per replicate and
// channel (committed and the chunk row being filled) and, with one replicate, squared
// deviations; the float image and variance (24); the PNG's 8-bit pixels and encoding (about 6);
// 96 more for copies; plus 10 % for what the estimate leaves out.
uint64_t render_host_bytes(int width, int height, unsigned replicates);

// Bytes per ray `mcrt bench` holds on the host (rays, hits, surface points, occlusion results).
uint64_t bench_host_bytes(int width, int height);

// MemAvailable from /proc/meminfo, lowered to the cgroup's memory.max − memory.current when that
// is smaller; 0 when neither can be read (then no check is made).
uint64_t available_host_bytes();

// Throws RuntimeError "<what> needs about N GiB of host memory; M GiB is available" when
// `needed` exceeds what is available.
void check_host_memory(const std::string& what, uint64_t needed);

}  // namespace mcrt
