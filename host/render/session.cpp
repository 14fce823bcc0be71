#include "render/session.h"

#include <atomic>
#include <chrono>

#include "common/activity.h"
#include "common/error.h"
#include "render/device_worker.h"

namespace mcrt {

std::shared_ptr<SessionScene> load_session_scene(const std::string& path,
                                                 const std::string& materials,
                                                 LightSelection selection,
                                                 const SceneSource& source,
                                                 const WarningSink& warn) {
    static std::atomic<uint64_t> next_id{1};
    RenderSettings named;
    named.materials = materials;
    const RenderVariants variants = resolve_variants(named);  // SettingError for a bad name

    auto loaded = std::make_shared<SessionScene>();
    loaded->path = path;
    loaded->materials = materials;
    loaded->id = next_id++;
    PreparedScene& prepared = loaded->prepared;
    const auto load_start = std::chrono::steady_clock::now();
    {
        const Activity activity("loading the scene");
        prepared.scene = read_scene(path, source, warn);
    }
    prepared.seconds_load =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    if (variants.materials->lambertian) make_lambertian(prepared.scene.materials);
    prepared.camera = choose_camera(prepared.scene, CameraChoice{});
    {
        const Activity activity("building the BVH");
        prepared.bvh = build_bvh(prepared.scene);
    }
    {
        // The camera's part of the layout is written at each render (write_camera): here only
        // its size matters, not its image's.
        const Activity activity("laying out the scene for the devices");
        prepared.gpu =
            make_gpu_scene(prepared.scene, prepared.bvh, prepared.camera, 1, 1, selection);
    }
    return loaded;
}

RenderPlan plan_session_render(SessionScene& scene, const RenderRequest& request,
                               const WarningSink& warn, const SceneSource& source) {
    RenderPlan plan = check_render_settings(request.settings, request.sky);
    if (plan.settings.materials != scene.materials)
        throw SettingError("materials", plan.settings.materials + ": the scene was loaded with " +
                                            scene.materials);
    const RenderSettings& s = plan.settings;
    PreparedScene& prepared = scene.prepared;
    prepared.camera = choose_camera(prepared.scene, request.camera);
    prepared.gpu.camera = make_gpu_camera(prepared.camera, s.width, s.height);
    if (warn && prepared.scene.triangle_count() == 0)
        warn(scene.path + ": the scene has no triangles");
    warn_unseen_lights(scene.path, plan, prepared.gpu, warn);
    plan_environment(plan, prepared.gpu, source);
    return finish_render_plan(std::move(plan), prepared.gpu);
}

std::shared_ptr<DeviceContext> process_device_context(const DeviceInfo& device) {
    static std::mutex mutex;
    // Never destroyed: a context lives as long as the programs cached_program keeps on it, the
    // life of the process.
    static auto* contexts = new std::map<cl_device_id, std::shared_ptr<DeviceContext>>();
    std::lock_guard<std::mutex> lock(mutex);
    std::shared_ptr<DeviceContext>& context = (*contexts)[device.device()];
    if (!context) context = std::make_shared<DeviceContext>(device);
    return context;
}

RenderSession::RenderSession(const std::vector<DeviceInfo>& devices, const WarningSink& warn) {
    for (const DeviceInfo& d : devices) {
        try {
            contexts_.push_back(process_device_context(d));
            device_list_.push_back(contexts_.back().get());
        } catch (const RuntimeError& e) {
            if (devices.size() == 1 || (contexts_.empty() && &d == &devices.back())) throw;
            if (warn)
                warn("skipping device " + std::to_string(d.index) + " ('" + d.name +
                     "'): " + e.what());
        }
    }
}

size_t RenderSession::uploaded_scenes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return uploads_.size();
}

RenderResult RenderSession::render(const std::shared_ptr<SessionScene>& scene,
                                   const RenderPlan& plan, const ProgressSink& progress,
                                   const RenderControl& control, const WarningSink& warn,
                                   const RemoteWorkers& remote) {
    std::lock_guard<std::mutex> lock(mutex_);
    // The buffers of scenes nobody holds any more go before anything is uploaded.
    for (auto it = uploads_.begin(); it != uploads_.end();)
        it = it->second.scene.expired() ? uploads_.erase(it) : std::next(it);
    SceneUploads& uploads = uploads_[scene->id];
    uploads.scene = scene;
    GpuSceneData& data = scene->prepared.gpu;
    const LightSelection selection = plan.variants.light_select->id;
    // The host holds one light selection's data at a time, built only for a device that has
    // not got it yet: a sweep that returns to a selection finds it on the devices (a light
    // tree of 10^6 lights takes 2 s to build, docs/BENCHMARKS.md).
    auto host_data = [&]() -> const GpuSceneData& {
        if (data.light_selection.selection != selection) {
            const Activity activity("laying out the scene for the devices");
            build_light_selection(data, selection);
        }
        return data;
    };

    const WorkerFactory make_worker = [&](const DeviceContext& device) {
        DeviceUpload& upload = uploads.devices[device.info.index];
        if (!upload.buffers) {
            const GpuSceneData& selected = host_data();
            const Activity activity("uploading the scene");
            upload.buffers = std::make_unique<GpuSceneBuffers>(device, selected, selection);
            upload.selections[selection] = {upload.buffers->light_selection,
                                            upload.buffers->light_tree_nodes};
        }
        auto kept = upload.selections.find(selection);
        if (kept == upload.selections.end()) {
            DeviceUpload::Selection added;
            added.buffer =
                upload_light_selection(device, host_data(), selection, &added.tree_nodes);
            kept = upload.selections.emplace(selection, added).first;
        }
        write_camera(device, *upload.buffers, data.camera);
        GpuSceneBuffers buffers = *upload.buffers;  // handles, sharing the device's buffers
        buffers.light_selection = kept->second.buffer;
        buffers.light_tree_nodes = kept->second.tree_nodes;
        return std::make_unique<DeviceWorker>(device, buffers, plan);
    };
    return render_with_workers(device_list_, make_worker, plan, progress, control, warn, remote);
}

}  // namespace mcrt
