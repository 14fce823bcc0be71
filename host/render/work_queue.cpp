#include "render/work_queue.h"

#include <algorithm>

#include "shared_types.h"

namespace mcrt {

WorkQueue::WorkQueue(uint32_t pixels, uint32_t spp)
    : pixels_(pixels),
      spp_(spp),
      chunks_((spp + MCRT_SAMPLES_PER_CHUNK - 1) / MCRT_SAMPLES_PER_CHUNK) {}

uint32_t WorkQueue::samples_in_chunk(uint32_t chunk) const {
    return std::min<uint32_t>(MCRT_SAMPLES_PER_CHUNK, spp_ - chunk * MCRT_SAMPLES_PER_CHUNK);
}

std::optional<WorkItem> WorkQueue::take(uint64_t target_samples, bool wait) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        if (abandoned_) return std::nullopt;
        if (!redo_.empty()) {
            WorkItem item = redo_.front();
            redo_.pop_front();
            ++in_flight_;
            return item;
        }
        bool first_row_out = next_chunk_ > 0;
        bool all_out = next_chunk_ >= chunks_;
        if (!all_out && !(stopped_ && first_row_out)) break;
        if (in_flight_ == 0 || !wait) return std::nullopt;
        changed_.wait(lock);
    }

    WorkItem item;
    item.seq = next_seq_++;
    item.chunk_begin = next_chunk_;
    const uint64_t row = uint64_t(pixels_) * MCRT_SAMPLES_PER_CHUNK;
    if (next_pixel_ == 0 && target_samples >= row) {
        // Whole chunks of every pixel.
        uint64_t k = std::max<uint64_t>(1, target_samples / row);
        item.chunk_end = uint32_t(std::min<uint64_t>(chunks_, next_chunk_ + k));
        item.pixel_begin = 0;
        item.pixel_end = pixels_;
        next_chunk_ = item.chunk_end;
    } else {
        // One chunk of a range of pixels.
        uint64_t n = std::max<uint64_t>(64, target_samples / samples_in_chunk(next_chunk_));
        item.chunk_end = next_chunk_ + 1;
        item.pixel_begin = next_pixel_;
        item.pixel_end = uint32_t(std::min<uint64_t>(pixels_, next_pixel_ + n));
        next_pixel_ = item.pixel_end;
        if (next_pixel_ == pixels_) {
            next_pixel_ = 0;
            ++next_chunk_;
        }
    }
    ++in_flight_;
    return item;
}

void WorkQueue::done(const WorkItem&) {
    std::lock_guard<std::mutex> lock(mutex_);
    --in_flight_;
    changed_.notify_all();
}

void WorkQueue::give_back(const WorkItem& item) {
    std::lock_guard<std::mutex> lock(mutex_);
    --in_flight_;
    redo_.push_back(item);
    // Redo in sequence order so results keep flowing to the accumulator.
    std::sort(redo_.begin(), redo_.end(),
              [](const WorkItem& a, const WorkItem& b) { return a.seq < b.seq; });
    changed_.notify_all();
}

void WorkQueue::stop() {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
    changed_.notify_all();
}

void WorkQueue::abandon() {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = abandoned_ = true;
    changed_.notify_all();
}

bool WorkQueue::stopped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stopped_;
}

}  // namespace mcrt
