#include "render/accumulator.h"

#include <algorithm>

namespace mcrt {

Accumulator::Accumulator(uint32_t pixels, uint32_t spp)
    : pixels_(pixels), spp_(spp), sum_(3 * size_t(pixels)), sum_sq_(3 * size_t(pixels)),
      row_sum_(3 * size_t(pixels)), row_sum_sq_(3 * size_t(pixels)) {}

void Accumulator::submit(BatchResult result) {
    uint64_t seq = result.item.seq;
    pending_.emplace(seq, std::move(result));
    for (auto it = pending_.find(next_seq_); it != pending_.end(); it = pending_.find(next_seq_)) {
        apply(it->second);
        pending_.erase(it);
        ++next_seq_;
    }
}

void Accumulator::apply(const BatchResult& r) {
    const WorkItem& item = r.item;
    const uint32_t chunks = item.chunk_count();
    for (uint32_t c = 0; c < chunks; ++c) {
        for (uint32_t p = 0; p < item.pixel_count(); ++p) {
            const gpu::float4& s = r.sums[size_t(p) * chunks + c];
            const gpu::float4& s2 = r.sums_sq[size_t(p) * chunks + c];
            size_t k = 3 * size_t(item.pixel_begin + p);
            // Within a row each pixel receives one chunk: the row buffer holds it exactly.
            row_sum_[k + 0] = s.x;
            row_sum_[k + 1] = s.y;
            row_sum_[k + 2] = s.z;
            row_sum_sq_[k + 0] = s2.x;
            row_sum_sq_[k + 1] = s2.y;
            row_sum_sq_[k + 2] = s2.z;
            row_nan_ += uint64_t(s.w);
            row_rays_ += uint64_t(s2.w);
        }
        row_pixels_ += item.pixel_count();
        if (row_pixels_ == pixels_) commit_row();
    }
}

void Accumulator::commit_row() {
    for (size_t k = 0; k < sum_.size(); ++k) {
        sum_[k] += row_sum_[k];
        sum_sq_[k] += row_sum_sq_[k];
    }
    nan_samples_ += row_nan_;
    rays_ += row_rays_;
    row_nan_ = row_rays_ = 0;
    row_pixels_ = 0;
    ++committed_chunks_;
}

uint32_t Accumulator::committed_spp() const {
    return std::min<uint64_t>(spp_, uint64_t(committed_chunks_) * MCRT_SAMPLES_PER_CHUNK);
}

Image Accumulator::image(int width, int height) const {
    Image img(width, height);
    uint32_t spp = committed_spp();
    img.spp = spp;
    if (spp == 0) return img;
    double n = spp;
    for (size_t k = 0; k < sum_.size(); ++k) {
        double mean = sum_[k] / n;
        img.rgb[k] = float(mean);
        // Variance of the pixel mean: the sample variance (n − 1 denominator) over n.
        double var = n > 1 ? std::max(0.0, (sum_sq_[k] - sum_[k] * mean) / (n - 1)) / n : 0.0;
        img.variance[k] = float(var);
    }
    return img;
}

}  // namespace mcrt
