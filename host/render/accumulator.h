// Adds batch results into the image in a fixed order, in double precision.
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "image/image.h"
#include "render/work_queue.h"
#include "shared_types.h"

namespace mcrt {

// Per-run sums of one work item, as reduce_chunks writes them: pixel-major, then chunk, then
// replicate: sums[(p · chunk_count() + c) · replicates + r].
struct BatchResult {
    WorkItem item;
    std::vector<gpu::ChunkSums> sums;
};

// Results may arrive in any order from any device; they are applied in WorkItem::seq order, so
// each pixel's chunks are merged in sample order and the image does not depend on batch sizes,
// devices or timing. A chunk row (one chunk of every pixel) enters the image only when complete,
// so a stopped render is an image of whole chunks (each replicate then has the same number of
// samples). Each pixel keeps, per replicate, the mean of its samples (and, with one replicate,
// their sum of squared deviations), merged chunk by chunk by Chan, Golub & LeVeque's pairwise
// update from the runs' shifted, scaled sums: nothing cancels, nothing overflows. Not
// thread-safe: the caller locks.
class Accumulator {
  public:
    Accumulator(uint32_t pixels, uint32_t spp, uint32_t replicates);
    void submit(BatchResult result);
    uint32_t committed_spp() const;  // samples per pixel in the image so far
    // The mean, and the variance of the mean: from the spread of the replicate means when there
    // are several (honest for correlated samples), else the samples' variance over n.
    // Variances beyond float's range are written as FLT_MAX and counted (variance_clamped).
    Image image(int width, int height) const;
    uint64_t nan_samples() const { return nan_samples_; }
    uint64_t rays() const { return rays_; }
    uint64_t path_vertices() const { return path_vertices_; }
    uint64_t roulette_ends() const { return roulette_ends_; }
    uint32_t replicates() const { return replicates_; }
    uint64_t variance_clamped() const { return variance_clamped_; }
    // Each replicate's own mean image, pixel-major then replicate then channel:
    // [(p · replicates + k) · 3 + c]; empty with one replicate.
    std::vector<float> replicate_means() const;

  private:
    void apply(const BatchResult& r);
    void commit_row();

    uint32_t pixels_, spp_, replicates_;
    uint64_t next_seq_ = 0;
    std::map<uint64_t, BatchResult> pending_;
    // Committed: per (pixel, replicate) 3 means; with one replicate also 3 squared deviations.
    std::vector<double> mean_, m2_;
    double n_ = 0;  // samples per replicate committed, the same for every pixel
    // The chunk row being filled: per (pixel, replicate) its run's mean and squared deviations.
    std::vector<double> row_mean_, row_m2_;
    double row_n_ = 0;         // samples per replicate in the row's runs
    uint32_t row_pixels_ = 0;  // pixels of that row applied so far
    uint64_t row_nan_ = 0, row_rays_ = 0, row_vertices_ = 0, row_roulette_ = 0;
    uint32_t committed_chunks_ = 0;
    uint64_t nan_samples_ = 0, rays_ = 0, path_vertices_ = 0, roulette_ends_ = 0;
    mutable uint64_t variance_clamped_ = 0;
};

}  // namespace mcrt
