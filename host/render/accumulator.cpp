#include "render/accumulator.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <mutex>
#include <system_error>
#include <thread>

namespace mcrt {

Accumulator::Accumulator(uint32_t pixels, uint32_t spp, uint32_t replicates)
    : pixels_(pixels),
      spp_(spp),
      replicates_(replicates),
      mean_(3 * size_t(pixels) * replicates),
      m2_(replicates == 1 ? 3 * size_t(pixels) : 0),
      row_mean_(mean_.size()),
      row_m2_(m2_.size()) {}

void Accumulator::submit(BatchResult result) {
    uint64_t seq = result.item.seq;
    pending_.emplace(seq, std::move(result));
    for (auto it = pending_.find(next_seq_); it != pending_.end(); it = pending_.find(next_seq_)) {
        apply(it->second);
        pending_.erase(it);
        ++next_seq_;
    }
}

namespace {

// 2^e exactly, as std::ldexp(1.0, e) gives it for the exponents the kernels write (|e| < 1000),
// without a call into libm per pixel and channel.
double power_of_two(int e) {
    e = std::clamp(e, -1022, 1023);
    uint64_t bits = uint64_t(1023 + e) << 52;
    double value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

// Runs body(begin, end) over [0, count) in contiguous parts on up to all cores: a GPU delivers a
// batch faster than one host thread merges it (docs/BENCHMARKS.md "On a GPU"). Each pixel's
// arithmetic is the same on any part, so the image does not depend on the number of threads.
template <class Body>
void for_pixel_ranges(size_t count, const Body& body) {
    constexpr size_t kMinimumPart = 32768;  // below this a thread costs more than it saves
    static const size_t cores = std::max(1u, std::min(16u, std::thread::hardware_concurrency()));
    const size_t parts = std::min(cores, std::max<size_t>(1, count / kMinimumPart));
    if (parts <= 1) {
        body(0, count);
        return;
    }
    std::vector<std::thread> threads;
    threads.reserve(parts - 1);
    const size_t step = (count + parts - 1) / parts;
    try {
        for (size_t begin = step; begin < count; begin += step)
            threads.emplace_back(
                [&body, begin, step, count] { body(begin, std::min(count, begin + step)); });
    } catch (const std::system_error&) {
        // No thread to be had (a process limit): the parts not started run here.
        for (size_t begin = step * (threads.size() + 1); begin < count; begin += step)
            body(begin, std::min(count, begin + step));
    }
    body(0, std::min(count, step));
    for (std::thread& t : threads) t.join();
}

}  // namespace

void Accumulator::apply(const BatchResult& r) {
    const WorkItem& item = r.item;
    const uint32_t chunks = item.chunk_count(), K = replicates_;
    const uint32_t pixel_count = item.pixel_count();
    for (uint32_t c = 0; c < chunks; ++c) {
        // The counters are integers: each part's sums added afterwards are exact in any order.
        struct Counts {
            uint64_t nan = 0, rays = 0, vertices = 0, roulette = 0;
            double n = 0;
        };
        std::mutex counts_mutex;
        Counts total;
        for_pixel_ranges(pixel_count, [&](size_t begin, size_t end) {
            Counts part;
            for (size_t p = begin; p < end; ++p) {
                for (uint32_t k = 0; k < K; ++k) {
                    const gpu::ChunkSums& s = r.sums[(p * chunks + c) * K + k];
                    const double n = s.sum_sq.w;
                    const size_t at = 3 * ((item.pixel_begin + p) * K + k);
                    const float shift[3] = {s.shift.x, s.shift.y, s.shift.z};
                    const float sum[3] = {s.sum.x, s.sum.y, s.sum.z};
                    const float sum_sq[3] = {s.sum_sq.x, s.sum_sq.y, s.sum_sq.z};
                    const float exponent[3] = {s.exponent.x, s.exponent.y, s.exponent.z};
                    // Within a row each pixel receives one run per replicate: the row holds it.
                    for (int ch = 0; ch < 3; ++ch) {
                        const double scale = power_of_two(int(exponent[ch]));
                        row_mean_[at + ch] = double(shift[ch]) + double(sum[ch]) * scale / n;
                        if (K == 1) {
                            const double d = double(sum[ch]);
                            row_m2_[at + ch] =
                                std::max(0.0, double(sum_sq[ch]) - d * d / n) * scale * scale;
                        }
                    }
                    part.n = n;  // the same for every pixel of a row: its chunk, over K
                    part.nan += uint64_t(s.shift.w);
                    part.rays += uint64_t(s.sum.w);
                    // Path vertices + 2^15 × roulette ends (kernels/core/shared_types.h).
                    const uint64_t path = uint64_t(s.exponent.w);
                    part.vertices += path & 0x7fff;
                    part.roulette += path >> 15;
                }
            }
            std::lock_guard<std::mutex> lock(counts_mutex);
            total.nan += part.nan;
            total.rays += part.rays;
            total.vertices += part.vertices;
            total.roulette += part.roulette;
            if (end > begin) total.n = part.n;
        });
        if (pixel_count > 0) row_n_ = total.n;
        row_nan_ += total.nan;
        row_rays_ += total.rays;
        row_vertices_ += total.vertices;
        row_roulette_ += total.roulette;
        row_pixels_ += pixel_count;
        if (row_pixels_ == pixels_) commit_row();
    }
}

void Accumulator::commit_row() {
    // Chan, Golub & LeVeque 1983: (n_a, mean_a, M2_a) ⊕ (n_b, mean_b, M2_b).
    const double n_a = n_, n_b = row_n_, n = n_a + n_b;
    for_pixel_ranges(mean_.size(), [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
            const double delta = row_mean_[k] - mean_[k];
            mean_[k] += delta * (n_b / n);
            if (!m2_.empty()) m2_[k] += row_m2_[k] + delta * delta * (n_a * n_b / n);
        }
    });
    n_ = n;
    nan_samples_ += row_nan_;
    rays_ += row_rays_;
    path_vertices_ += row_vertices_;
    roulette_ends_ += row_roulette_;
    row_nan_ = row_rays_ = row_vertices_ = row_roulette_ = 0;
    row_pixels_ = 0;
    ++committed_chunks_;
}

uint32_t Accumulator::committed_spp() const {
    return std::min<uint64_t>(spp_, uint64_t(committed_chunks_) * MCRT_SAMPLES_PER_CHUNK);
}

std::vector<float> Accumulator::replicate_means() const {
    if (replicates_ == 1) return {};
    return std::vector<float>(mean_.begin(), mean_.end());
}

Image Accumulator::image(int width, int height) const {
    Image img(width, height);
    img.spp = committed_spp();
    if (img.spp == 0) return img;
    const uint32_t K = replicates_;
    const double spp = img.spp;
    variance_clamped_ = 0;
    for (size_t p = 0; p < size_t(pixels_); ++p)
        for (int ch = 0; ch < 3; ++ch) {
            double mean = 0, var = 0;
            if (K == 1) {
                mean = mean_[3 * p + ch];
                // The sample variance (n − 1 denominator) over n: the variance of the mean.
                var = spp > 1 ? m2_[3 * p + ch] / (spp - 1) / spp : 0.0;
            } else {
                for (uint32_t k = 0; k < K; ++k) mean += mean_[3 * (p * K + k) + ch] / K;
                // The spread of K independent replicate means: the variance of their mean.
                for (uint32_t k = 0; k < K; ++k) {
                    const double d = mean_[3 * (p * K + k) + ch] - mean;
                    var += d * d;
                }
                var /= double(K) * double(K - 1);
            }
            img.rgb[3 * p + ch] = float(mean);
            if (var > double(FLT_MAX)) {
                var = FLT_MAX;
                ++variance_clamped_;
            }
            img.variance[3 * p + ch] = float(var);
        }
    return img;
}

}  // namespace mcrt
