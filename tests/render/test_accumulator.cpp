// The accumulator merges batch results on every core: the image must be the same bits as one
// thread's merge, whatever the order in which the results arrive.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "render/accumulator.h"

using namespace mcrt;

namespace {

// One pixel's run of `n` samples as the kernels write it (shift, scaled sums, exponent).
gpu::ChunkSums run_sums(std::mt19937& rng, float n) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::uniform_int_distribution<int> e(-20, 20);
    gpu::ChunkSums s{};
    s.shift = {u(rng), u(rng), u(rng), float(e(rng) > 18)};
    s.sum = {u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f, float(1 + e(rng) + 20)};
    s.sum_sq = {u(rng), u(rng), u(rng), n};
    s.exponent = {float(e(rng)), float(e(rng)), float(e(rng)), float(3 + (1 << 15))};
    return s;
}

}  // namespace

TEST_CASE("the accumulator's image is one thread's merge, bit for bit, in any arrival order",
          "[accumulator]") {
    // Enough pixels that the merge runs in several parts on any machine with two cores or more.
    const uint32_t pixels = 3 * 65536 + 17, spp = 4 * MCRT_SAMPLES_PER_CHUNK;
    const uint32_t K = GENERATE(1u, 2u);
    const uint32_t chunks = spp / MCRT_SAMPLES_PER_CHUNK;
    const float n = float(MCRT_SAMPLES_PER_CHUNK) / float(K);
    std::mt19937 rng(7);
    // Work items as the work queue makes them: whole rows of several chunks, or a part of one
    // chunk's row (here two chunks of every pixel, then each later chunk in thirds), delivered
    // in a shuffled order.
    std::vector<BatchResult> results;
    uint64_t seq = 0;
    auto add_item = [&](uint32_t chunk_begin, uint32_t chunk_end, uint32_t pixel_begin,
                        uint32_t pixel_end) {
        BatchResult r;
        r.item = {seq++, chunk_begin, chunk_end, pixel_begin, pixel_end};
        for (uint32_t i = 0; i < r.item.pixel_count() * r.item.chunk_count() * K; ++i)
            r.sums.push_back(run_sums(rng, n));
        results.push_back(std::move(r));
    };
    add_item(0, 2, 0, pixels);
    const uint32_t third = pixels / 3 + 1;
    for (uint32_t c = 2; c < chunks; ++c)
        for (uint32_t p = 0; p < pixels; p += third)
            add_item(c, c + 1, p, std::min(pixels, p + third));
    // One thread's merge, written out: each pixel's runs in chunk order (Chan, Golub & LeVeque).
    std::vector<double> mean(3 * size_t(pixels) * K, 0.0), m2(3 * size_t(pixels), 0.0);
    uint64_t rays = 0, vertices = 0, roulette = 0, nan = 0;
    std::vector<const BatchResult*> by_seq;
    for (const BatchResult& r : results) by_seq.push_back(&r);
    for (uint32_t c = 0; c < chunks; ++c) {
        const double n_a = double(c) * n, n_b = n, n_total = n_a + n_b;
        for (const BatchResult* r : by_seq) {
            if (c < r->item.chunk_begin || c >= r->item.chunk_end) continue;
            const uint32_t item_chunks = r->item.chunk_count();
            for (uint32_t p = 0; p < r->item.pixel_count(); ++p)
                for (uint32_t k = 0; k < K; ++k) {
                    const gpu::ChunkSums& s =
                        r->sums[(size_t(p) * item_chunks + (c - r->item.chunk_begin)) * K + k];
                    const size_t at = 3 * ((size_t(r->item.pixel_begin) + p) * K + k);
                    const float shift[3] = {s.shift.x, s.shift.y, s.shift.z};
                    const float sum[3] = {s.sum.x, s.sum.y, s.sum.z};
                    const float sum_sq[3] = {s.sum_sq.x, s.sum_sq.y, s.sum_sq.z};
                    const float e[3] = {s.exponent.x, s.exponent.y, s.exponent.z};
                    for (int ch = 0; ch < 3; ++ch) {
                        const double scale = std::ldexp(1.0, int(e[ch]));
                        const double row_mean = double(shift[ch]) + double(sum[ch]) * scale / n;
                        const double delta = row_mean - mean[at + ch];
                        mean[at + ch] += delta * (n_b / n_total);
                        if (K == 1) {
                            const double d = double(sum[ch]);
                            const double row_m2 =
                                std::max(0.0, double(sum_sq[ch]) - d * d / n) * scale * scale;
                            m2[at + ch] += row_m2 + delta * delta * (n_a * n_b / n_total);
                        }
                    }
                    nan += uint64_t(s.shift.w);
                    rays += uint64_t(s.sum.w);
                    vertices += uint64_t(s.exponent.w) & 0x7fff;
                    roulette += uint64_t(s.exponent.w) >> 15;
                }
        }
    }
    std::shuffle(results.begin(), results.end(), rng);
    Accumulator accumulator(pixels, spp, K);
    for (BatchResult& r : results) accumulator.submit(std::move(r));
    REQUIRE(accumulator.committed_spp() == spp);
    CHECK(accumulator.rays() == rays);
    CHECK(accumulator.path_vertices() == vertices);
    CHECK(accumulator.roulette_ends() == roulette);
    CHECK(accumulator.nan_samples() == nan);
    const Image image = accumulator.image(int(pixels), 1);
    size_t differing = 0;
    for (size_t p = 0; p < pixels; ++p)
        for (int ch = 0; ch < 3; ++ch) {
            double expected = 0;
            if (K == 1) {
                expected = mean[3 * p + ch];
                const double variance = m2[3 * p + ch] / (spp - 1.0) / spp;
                if (float(variance) != image.variance[3 * p + ch]) ++differing;
            } else {
                for (uint32_t k = 0; k < K; ++k) expected += mean[3 * (p * K + k) + ch] / K;
            }
            if (float(expected) != image.rgb[3 * p + ch]) ++differing;
        }
    CHECK(differing == 0);
}
