// The host's merge of batch results (render/accumulator.h) alone: a 1024x1024, 1024 spp render's
// 64 chunk rows, each delivered as four quarter-row batches of synthetic sums (as a GPU delivers
// them, docs/BENCHMARKS.md "On a GPU"); prints the time in Accumulator::submit per pixel and chunk.
//
//   build/mcrt_accumulator_bench [REPLICATES]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "render/accumulator.h"

using namespace mcrt;

int main(int argc, char** argv) {
    const uint32_t pixels = 1024 * 1024, spp = 1024;
    const uint32_t K = argc > 1 ? uint32_t(std::max(1, std::atoi(argv[1]))) : 1;
    const uint32_t chunks_total = spp / MCRT_SAMPLES_PER_CHUNK;
    const uint32_t item_pixels = pixels / 4;
    Accumulator accumulator(pixels, spp, K);
    std::vector<gpu::ChunkSums> sums(size_t(item_pixels) * K);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0, 1);
    for (auto& s : sums) {
        s.shift = {u(rng), u(rng), u(rng), 0};
        s.sum = {u(rng), u(rng), u(rng), 40};
        s.sum_sq = {u(rng), u(rng), u(rng), float(MCRT_SAMPLES_PER_CHUNK) / K};
        s.exponent = {0, 0, 0, 3};
    }
    uint64_t seq = 0;
    double seconds = 0;
    for (uint32_t c = 0; c < chunks_total; ++c)
        for (uint32_t p = 0; p < pixels; p += item_pixels) {
            BatchResult result;
            result.item = {seq++, c, c + 1, p, p + item_pixels};
            result.sums = sums;
            const auto t0 = std::chrono::steady_clock::now();
            accumulator.submit(std::move(result));
            seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
    const Image image = accumulator.image(1024, 1024);
    std::printf(
        "replicates %u: %llu batches, %.3f s in submit, %.1f ns per pixel and chunk "
        "(pixel 12345: %.9g)\n",
        K, (unsigned long long)seq, seconds, 1e9 * seconds / (double(pixels) * chunks_total),
        image.rgb[12345]);
    return 0;
}
