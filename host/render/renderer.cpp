#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include "common/activity.h"
#include "common/error.h"
#include "render/accumulator.h"
#include "render/agreement.h"
#include "render/device_worker.h"
#include "render/plan.h"
#include "render/render_program.h"
#include "render/render_worker.h"
#include "render/variants.h"
#include "render/work_queue.h"

namespace mcrt {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

uint32_t batch_samples_per_pixel(uint32_t requested, int width, int height, uint32_t spp) {
    const uint32_t chunk = MCRT_SAMPLES_PER_CHUNK;
    uint64_t batch = requested;
    if (batch == 0) batch = (uint64_t(1) << 22) / (uint64_t(width) * height);
    batch = std::max<uint64_t>(chunk, (batch + chunk - 1) / chunk * chunk);
    uint64_t spp_chunks = (uint64_t(spp) + chunk - 1) / chunk * chunk;
    return uint32_t(std::min(batch, spp_chunks));
}

RenderResult render(const std::vector<const DeviceContext*>& devices, const GpuSceneData& scene,
                    const RenderPlan& plan, const ProgressSink& progress,
                    const RenderControl& control,
                    const std::function<void(const std::string&)>& warn,
                    const RemoteWorkers& remote) {
    return render_with_workers(
        devices,
        [&](const DeviceContext& d) { return std::make_unique<DeviceWorker>(d, scene, plan); },
        plan, progress, control, warn, remote);
}

RenderResult render_with_workers(const std::vector<const DeviceContext*>& devices,
                                 const WorkerFactory& make_worker, const RenderPlan& plan,
                                 const ProgressSink& progress, const RenderControl& control,
                                 const std::function<void(const std::string&)>& warn,
                                 const RemoteWorkers& remote) {
    const Activity activity("building the kernels and rendering");
    auto start = std::chrono::steady_clock::now();
    const RenderSettings& settings = plan.settings;
    const uint32_t pixels = uint32_t(settings.width) * uint32_t(settings.height);
    const uint64_t fixed_batch = plan.fixed_batch;

    // Set up every device; one that cannot hold the scene is skipped with a warning.
    std::vector<std::unique_ptr<RenderWorker>> workers;
    std::string last_error;
    for (const DeviceContext* d : devices) {
        try {
            workers.push_back(make_worker(*d));
        } catch (const RuntimeError& e) {
            if (devices.size() == 1 && !remote) throw;
            last_error = e.what();
            if (warn)
                warn("skipping device " + std::to_string(d->info.index) + " ('" + d->info.name +
                     "'): " + e.what());
        }
    }
    if (control.launching && !remote) control.launching();
    check_agreement(workers, workers.size(), settings, warn);
    if (remote) {
        for (auto& w : remote()) workers.push_back(std::move(w));
        if (control.launching) control.launching();
    }
    if (workers.empty()) throw RuntimeError("no device can render this scene: " + last_error);
    bool any_working = false;
    for (const auto& w : workers) any_working |= !w->report.retired;
    if (!any_working)
        throw RuntimeError("every device failed; no image was completed: " + last_error);

    RenderResult result;
    result.seconds_build = seconds_since(start);
    WorkQueue queue(pixels, settings.spp);
    Accumulator acc(pixels, settings.spp, settings.replicates);
    std::mutex acc_mutex;
    // Signalled by the device threads when a batch is in the image or a device retires, so that
    // the watch loop below sees the end at once instead of at its next 20 ms tick, as long as a
    // whole small render (docs/BENCHMARKS.md, "Start-up: from the command to the first sample").
    std::condition_variable progress_made;

    auto device_reports = [&] {
        std::vector<DeviceReport> r;
        for (const auto& w : workers) r.push_back(w->report);
        return r;
    };
    // Each device keeps up to pipeline_depth() items started (one until its first result has
    // measured its speed, so that the second is sized by it), and commits them in order.
    std::atomic<size_t> loops_ended{0};
    auto device_loop = [&](RenderWorker& worker, std::optional<WorkItem> item) {
        struct Ended {  // counted however the loop ends, under the lock the watch loop waits on
            std::atomic<size_t>& n;
            std::mutex& m;
            std::condition_variable& cv;
            ~Ended() {
                std::lock_guard<std::mutex> lock(m);
                ++n;
                cv.notify_all();
            }
        } ended{loops_ended, acc_mutex, progress_made};
        std::deque<WorkItem> started;
        for (;;) {
            BatchResult r;
            try {
                for (;;) {  // top up the pipeline
                    if (!item) {
                        size_t depth = worker.report.batches == 0 ? 1 : worker.pipeline_depth();
                        if (started.size() >= depth) break;
                        // Under a time limit, no second launch that would only start after it:
                        // it would run past the limit whole (the stop lets started work drain).
                        if (!started.empty() && control.time_limit > 0) {
                            double per_batch =
                                worker.report.seconds_busy / double(worker.report.batches);
                            if (seconds_since(start) + double(started.size()) * per_batch >=
                                control.time_limit)
                                break;
                        }
                        item = queue.take(worker.target_samples(), started.empty());
                        if (!item) break;
                    }
                    worker.start(*item);
                    started.push_back(*item);
                    item.reset();
                }
                if (started.empty()) return;
                r = worker.finish();
            } catch (const RuntimeError& e) {
                std::lock_guard<std::mutex> lock(acc_mutex);
                worker.report.retired = true;
                const std::string rank = worker.report.rank > 0
                                             ? "rank " + std::to_string(worker.report.rank) + " "
                                             : "";
                if (warn)
                    warn(rank + "device " + std::to_string(worker.report.index) + " ('" +
                         worker.report.name +
                         "') failed and is retired; its work is redone on the other devices: " +
                         e.what());
                if (item) queue.give_back(*item);
                for (const WorkItem& w : started) queue.give_back(w);
                progress_made.notify_all();
                return;
            }
            std::lock_guard<std::mutex> lock(acc_mutex);
            if (result.seconds_first_batch == 0) result.seconds_first_batch = seconds_since(start);
            worker.commit_report();
            acc.submit(std::move(r));
            queue.done(started.front());
            started.pop_front();
            progress_made.notify_all();
        }
    };
    // Every device starts with a probe launch handed out here, so each one measures its speed
    // and none is starved by a faster one that starts first; the probes leave most of the work
    // to the dynamic phase.
    const uint64_t total_samples = uint64_t(pixels) * settings.spp;
    // Small (at most 4096 samples: a device a thousand times slower than PoCL still answers
    // within a second), then each device's launches grow by its own measured speed.
    const uint64_t probe = std::clamp<uint64_t>(total_samples / (8 * workers.size()), 1024, 4096);
    std::vector<std::thread> threads;
    try {
        for (auto& w : workers)
            if (!w->report.retired)
                threads.emplace_back(device_loop, std::ref(*w),
                                     queue.take(fixed_batch > 0 ? fixed_batch : probe));
    } catch (const std::system_error&) {
        // No thread to be had (EAGAIN): those started end with the queue, then the error is told.
        queue.abandon();
        for (std::thread& t : threads) t.join();
        throw;
    }

    // Watch the clock, the interrupt flag and the progress until the devices are done.
    auto all_retired = [&] {
        for (const auto& w : workers)
            if (!w->report.retired) return false;
        return true;
    };
    // After a stop the first chunk row is finished (so that every pixel has samples), unless
    // that takes more than kStopGraceSeconds (a slow device): then the render is abandoned.
    constexpr double kStopGraceSeconds = 3.0;
    double stopped_at = 0;
    for (;;) {
        {
            std::lock_guard<std::mutex> lock(acc_mutex);
            if (progress) progress(acc.committed_spp(), settings.spp, device_reports());
            if (acc.committed_spp() >= settings.spp || all_retired() ||
                loops_ended == threads.size())
                break;
        }
        double elapsed = seconds_since(start);
        if (result.stopped_by.empty() && control.time_limit > 0 && elapsed >= control.time_limit)
            result.stopped_by = "time limit";
        if (result.stopped_by.empty() && control.interrupted && *control.interrupted)
            result.stopped_by = "interrupt";
        if (!result.stopped_by.empty() && stopped_at == 0) {
            stopped_at = elapsed;
            queue.stop();  // hand-out stops after the first chunk row; in-flight work drains
            // Another rank's device that does not answer within the grace is taken for dead,
            // before the supervisor's own grace for a launch ends (kSupervisorGraceSeconds).
            for (auto& w : workers) w->stopping(kStopGraceSeconds);
        }
        if (stopped_at > 0 && elapsed - stopped_at > kStopGraceSeconds) {
            std::lock_guard<std::mutex> lock(acc_mutex);
            if (acc.committed_spp() == 0) queue.abandon();
        }
        std::unique_lock<std::mutex> lock(acc_mutex);
        progress_made.wait_for(lock, std::chrono::milliseconds(20), [&] {
            return acc.committed_spp() >= settings.spp || all_retired() ||
                   loops_ended == threads.size();
        });
    }
    for (std::thread& t : threads) t.join();
    result.seconds_render_wall = seconds_since(start) - result.seconds_build;

    if (acc.committed_spp() == 0 && !result.stopped_by.empty())
        throw RuntimeError(
            "stopped by " + result.stopped_by + " before every pixel had its first " +
            std::to_string(std::min<uint32_t>(MCRT_SAMPLES_PER_CHUNK, settings.spp)) +
            " samples; no image was written");
    if (acc.committed_spp() == 0 ||
        (result.stopped_by.empty() && acc.committed_spp() < settings.spp))
        throw RuntimeError("every device failed; no image was completed");
    if (progress) progress(acc.committed_spp(), settings.spp, device_reports());
    result.spp = acc.committed_spp();
    result.image = acc.image(settings.width, settings.height);
    result.nan_samples = acc.nan_samples();
    result.replicates = acc.replicates();
    if (control.keep_replicate_means) result.replicate_means = acc.replicate_means();
    result.variance_clamped = acc.variance_clamped();
    result.rays = acc.rays();
    result.path_vertices = acc.path_vertices();
    result.roulette_ends = acc.roulette_ends();
    result.devices = device_reports();
    for (const DeviceReport& d : result.devices) result.seconds_render += d.seconds_busy;
    return result;
}

RenderResult render(const std::vector<const DeviceContext*>& devices, const GpuSceneData& scene,
                    const RenderSettings& settings, const ProgressSink& progress,
                    const RenderControl& control,
                    const std::function<void(const std::string&)>& warn,
                    const RemoteWorkers& remote) {
    const RenderPlan plan = make_render_plan(settings, scene);
    return render(devices, scene, plan, progress, control, warn, remote);
}

RenderResult render(const DeviceContext& device, const GpuSceneData& scene,
                    const RenderSettings& settings) {
    return render(std::vector<const DeviceContext*>{&device}, scene, settings);
}

}  // namespace mcrt
