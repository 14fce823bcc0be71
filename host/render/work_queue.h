// Hands out ranges of (sample chunk, pixel) to whichever device is free, in a fixed sequence.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>

namespace mcrt {

// Samples [16·chunk_begin, min(16·chunk_end, spp)) of pixels [pixel_begin, pixel_end). Either one
// chunk of a pixel range, or whole chunks of every pixel. seq is the hand-out order, which is
// chunk-major, so applying results in seq order adds each pixel's chunks in sample order.
struct WorkItem {
    uint64_t seq = 0;
    uint32_t chunk_begin = 0, chunk_end = 0;
    uint32_t pixel_begin = 0, pixel_end = 0;

    uint32_t pixel_count() const { return pixel_end - pixel_begin; }
    uint32_t chunk_count() const { return chunk_end - chunk_begin; }
};

class WorkQueue {
  public:
    WorkQueue(uint32_t pixels, uint32_t spp);

    // The next item of about target_samples samples (never fewer than one chunk of 64 pixels),
    // or nothing when the render is complete or stopped. Blocks while nothing is left to hand
    // out but items are still in flight, since a failing device may give one back; with
    // `wait` false returns nothing instead (a device topping up its pipeline must not wait for
    // the items it holds itself).
    std::optional<WorkItem> take(uint64_t target_samples, bool wait = true);
    void done(const WorkItem& item);       // the item's result has been delivered
    void give_back(const WorkItem& item);  // its device failed: another device redoes it
    // Stops handing out new items once the first chunk row is handed out, so a stopped render
    // still completes at least one sample per pixel.
    void stop();
    // Stops handing out anything, the first chunk row's rest too (a stop that the first row would
    // hold up for long on a slow device): the render then has no image.
    void abandon();
    bool stopped() const;
    uint32_t samples_in_chunk(uint32_t chunk) const;

  private:
    const uint32_t pixels_, spp_, chunks_;
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    uint32_t next_chunk_ = 0, next_pixel_ = 0;
    uint64_t next_seq_ = 0;
    int in_flight_ = 0;
    bool stopped_ = false, abandoned_ = false;
    std::deque<WorkItem> redo_;
};

}  // namespace mcrt
