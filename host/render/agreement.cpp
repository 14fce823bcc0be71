#include "render/agreement.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <optional>
#include <system_error>
#include <thread>

#include "common/error.h"

namespace mcrt {

namespace {

std::string hex_float(float v) {
    char text[32];
    std::snprintf(text, sizeof text, "%a", double(v));
    return text;
}

// The item every local device renders before its samples may enter the image: the first chunk
// of up to 64 pixels about the image's centre, where the scene is most likely seen.
WorkItem agreement_item(uint32_t pixels, int width, int height) {
    const uint32_t centre = uint32_t(height / 2) * uint32_t(width) + uint32_t(width / 2);
    WorkItem item;
    item.chunk_begin = 0;
    item.chunk_end = 1;
    item.pixel_begin = std::min(centre - std::min(centre, 32u), pixels - std::min(pixels, 64u));
    item.pixel_end = std::min(pixels, item.pixel_begin + 64u);
    return item;
}

}  // namespace

void check_agreement(std::vector<std::unique_ptr<RenderWorker>>& workers, size_t count,
                     const RenderSettings& settings,
                     const std::function<void(const std::string&)>& warn) {
    if (count < 2) return;
    const uint32_t pixels = uint32_t(settings.width) * uint32_t(settings.height);
    const WorkItem item = agreement_item(pixels, settings.width, settings.height);
    auto name = [&](size_t i) {
        return "device " + std::to_string(workers[i]->report.index) + " ('" +
               workers[i]->report.name + "')";
    };
    std::vector<std::optional<BatchResult>> results(count);
    std::vector<std::thread> threads;
    std::vector<std::string> failures(count);
    try {
        for (size_t i = 0; i < count; ++i)
            threads.emplace_back([&, i] {
                try {
                    results[i] = workers[i]->run(item);
                } catch (const RuntimeError& e) {
                    failures[i] = e.what();
                }
            });
    } catch (const std::system_error&) {
        for (std::thread& t : threads) t.join();  // no thread to be had: join, then tell it
        throw;
    }
    for (std::thread& t : threads) t.join();
    auto same = [&](size_t a, size_t b) {
        const auto &x = results[a]->sums, &y = results[b]->sums;
        return x.size() == y.size() &&
               std::memcmp(x.data(), y.data(), x.size() * sizeof(gpu::ChunkSums)) == 0;
    };
    // The agreeing groups, by their first member; the winner is the largest, earliest first.
    size_t winner = count, winner_size = 0;
    for (size_t i = 0; i < count; ++i) {
        if (!results[i]) continue;
        size_t size = 0;
        for (size_t j = 0; j < count; ++j) size += results[j] && same(i, j);
        if (size > winner_size) winner = i, winner_size = size;
    }
    size_t answered = 0;
    for (size_t i = 0; i < count; ++i) answered += results[i].has_value();
    const std::string kept = 2 * winner_size > answered
                                 ? "the image is the majority's alone"
                                 : "no majority decides, so the image is the first listed "
                                   "device's alone";
    for (size_t i = 0; i < count; ++i) {
        if (!results[i]) {
            workers[i]->report.retired = true;
            if (warn)
                warn(name(i) + " failed and is retired; its work is redone on the other devices: " +
                     failures[i]);
            continue;
        }
        if (same(i, winner)) continue;
        workers[i]->report.retired = true;
        // The first differing float of the two devices' sums.
        const auto &x = results[i]->sums, &y = results[winner]->sums;
        const float* a = reinterpret_cast<const float*>(x.data());
        const float* b = reinterpret_cast<const float*>(y.data());
        const size_t floats = std::min(x.size(), y.size()) * sizeof(gpu::ChunkSums) / sizeof(float);
        size_t k = 0;
        while (k < floats && std::memcmp(a + k, b + k, sizeof(float)) == 0) ++k;
        const size_t per_run = sizeof(gpu::ChunkSums) / sizeof(float);
        const uint32_t pixel = item.pixel_begin + uint32_t(k / per_run / settings.replicates);
        std::string where = k < floats
                                ? "at pixel (" + std::to_string(pixel % uint32_t(settings.width)) +
                                      ", " + std::to_string(pixel / uint32_t(settings.width)) +
                                      "), " + hex_float(a[k]) + " against " + hex_float(b[k])
                                : "in the number of values";
        if (warn)
            warn(name(i) + " disagrees with " + name(winner) +
                 " on the samples every device renders first (" + where + "): retired; " + kept);
    }
}

}  // namespace mcrt
