// Adds batch results into the image in a fixed order, in double precision.
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "image/image.h"
#include "render/work_queue.h"
#include "shared_types.h"

namespace mcrt {

// Per-chunk sums of one work item, as reduce_chunks writes them: pixel-major, chunk_count()
// entries per pixel.
struct BatchResult {
    WorkItem item;
    std::vector<gpu::float4> sums, sums_sq;
};

// Results may arrive in any order from any device; they are applied in WorkItem::seq order, so
// each pixel's chunk sums are added in sample order and the image does not depend on batch
// sizes, devices or timing. A chunk row (one chunk of every pixel) enters the image only when
// complete, so a stopped render is an image of whole chunks. Not thread-safe: the caller locks.
class Accumulator {
public:
    Accumulator(uint32_t pixels, uint32_t spp);
    void submit(BatchResult result);
    uint32_t committed_spp() const;  // samples per pixel in the image so far
    Image image(int width, int height) const;
    uint64_t nan_samples() const { return nan_samples_; }
    uint64_t rays() const { return rays_; }

private:
    void apply(const BatchResult& r);
    void commit_row();

    uint32_t pixels_, spp_;
    uint64_t next_seq_ = 0;
    std::map<uint64_t, BatchResult> pending_;
    std::vector<double> sum_, sum_sq_;          // committed: 3 per pixel
    std::vector<double> row_sum_, row_sum_sq_;  // the chunk row being filled
    uint32_t row_pixels_ = 0;                   // pixels of that row applied so far
    uint64_t row_nan_ = 0, row_rays_ = 0;
    uint32_t committed_chunks_ = 0;
    uint64_t nan_samples_ = 0, rays_ = 0;
};

}  // namespace mcrt
