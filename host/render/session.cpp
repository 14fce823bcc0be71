#include "render/session.h"

#include <sys/stat.h>

#include <algorithm>
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
                               const WarningSink& warn, const SceneSource& source,
                               EnvironmentCache* environments) {
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
    if (environments && !s.env.empty() && !source.bundle && !source.record) {
        // plan_environment with the session's map.
        {
            const Activity activity("loading the environment map");
            plan.environment = environments->load(s.env, s.env_scale, s.env_rotate);
        }
        plan.environment_steps = s.sky_light
                                     ? environment_pmf_steps(*plan.environment, prepared.gpu,
                                                             plan.variants.light_select->id)
                                     : 0;
    } else {
        plan_environment(plan, prepared.gpu, source);
    }
    return finish_render_plan(std::move(plan), prepared.gpu);
}

std::optional<EnvironmentCache::FileIdentity> EnvironmentCache::identify(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
    FileIdentity id;
    id.device = uint64_t(st.st_dev);
    id.inode = uint64_t(st.st_ino);
    id.size = uint64_t(st.st_size);
    id.mtime_ns = int64_t(st.st_mtim.tv_sec) * 1000000000 + int64_t(st.st_mtim.tv_nsec);
    return id;
}

std::shared_ptr<const EnvironmentLight> EnvironmentCache::load(const std::string& path, float scale,
                                                               float rotate_deg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::optional<FileIdentity> before = identify(path);
    auto kept = maps_.find(path);
    if (before && kept != maps_.end() && kept->second.file == *before &&
        kept->second.scale == scale && kept->second.rotate_deg == rotate_deg) {
        kept->second.last_use = ++uses_;
        return kept->second.light;
    }
    ++reads_;
    std::shared_ptr<const EnvironmentLight> light =
        load_environment_light(path, scale, rotate_deg, nullptr, nullptr);
    // Kept only when the file did not change while it was read.
    const std::optional<FileIdentity> after = identify(path);
    if (before && after && *before == *after) {
        if (kept == maps_.end() && maps_.size() >= kMaxMaps)
            maps_.erase(std::min_element(maps_.begin(), maps_.end(), [](auto& a, auto& b) {
                return a.second.last_use < b.second.last_use;
            }));
        maps_[path] = Entry{*after, scale, rotate_deg, light, ++uses_};
    } else if (kept != maps_.end()) {
        maps_.erase(kept);
    }
    return light;
}

uint64_t EnvironmentCache::reads() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return reads_;
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

uint64_t RenderSession::environment_uploads() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return environment_upload_count_;
}

size_t RenderSession::uploaded_scenes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return uploads_.size();
}

RenderSession::SceneUploads& RenderSession::uploads_of(const std::shared_ptr<SessionScene>& scene) {
    // The buffers of scenes nobody holds any more go before anything is uploaded.
    for (auto it = uploads_.begin(); it != uploads_.end();)
        it = it->second.scene.expired() ? uploads_.erase(it) : std::next(it);
    SceneUploads& uploads = uploads_[scene->id];
    uploads.scene = scene;
    return uploads;
}

std::unique_ptr<DeviceWorker> RenderSession::make_worker(SceneUploads& uploads, SessionScene& scene,
                                                         const RenderPlan& plan,
                                                         const DeviceContext& device) {
    GpuSceneData& data = scene.prepared.gpu;
    const LightSelection selection = plan.variants.light_select->id;
    // The host holds one light selection's data at a time, built only for a device that has
    // not got it yet: a sweep that returns to a selection finds it on the devices (a light
    // tree of many lights is slow to build: docs/BENCHMARKS.md, "Light selection").
    auto host_data = [&]() -> const GpuSceneData& {
        if (data.light_selection.selection != selection) {
            const Activity activity("laying out the scene for the devices");
            build_light_selection(data, selection);
        }
        return data;
    };
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
        added.buffer = upload_light_selection(device, host_data(), selection, &added.tree_nodes);
        kept = upload.selections.emplace(selection, added).first;
    }
    write_camera(device, *upload.buffers, data.camera);
    GpuSceneBuffers buffers = *upload.buffers;  // handles, sharing the device's buffers
    buffers.light_selection = kept->second.buffer;
    buffers.light_tree_nodes = kept->second.tree_nodes;
    cl::Buffer environment;
    if (plan.environment) {
        EnvironmentUpload& kept_map = environment_uploads_[device.info.index];
        if (kept_map.light != plan.environment) {
            kept_map = {};  // the previous map's buffer released before the next is made
            const Activity activity("uploading the environment map");
            kept_map.buffer = upload_environment(device, plan.environment.get());
            kept_map.light = plan.environment;
            ++environment_upload_count_;
        }
        environment = kept_map.buffer;
    }
    return std::make_unique<DeviceWorker>(device, buffers, plan, environment);
}

RenderResult RenderSession::render(const std::shared_ptr<SessionScene>& scene,
                                   const RenderPlan& plan, const ProgressSink& progress,
                                   const RenderControl& control, const WarningSink& warn,
                                   const RemoteWorkers& remote) {
    std::lock_guard<std::mutex> lock(mutex_);
    SceneUploads& uploads = uploads_of(scene);
    const WorkerFactory make = [&](const DeviceContext& device) {
        return make_worker(uploads, *scene, plan, device);
    };
    return render_with_workers(device_list_, make, plan, progress, control, warn, remote);
}

void RenderSession::serve(const std::shared_ptr<SessionScene>& scene, const RenderPlan& plan,
                          const Serve& serve, const WarningSink& warn) {
    std::lock_guard<std::mutex> lock(mutex_);
    SceneUploads& uploads = uploads_of(scene);
    std::vector<std::unique_ptr<DeviceWorker>> workers;
    for (const DeviceContext* d : device_list_) {
        try {
            workers.push_back(make_worker(uploads, *scene, plan, *d));
        } catch (const std::exception& e) {
            if (warn)
                warn("skipping device " + std::to_string(d->info.index) + " ('" + d->info.name +
                     "'): " + e.what());
        }
    }
    serve(workers);
}

}  // namespace mcrt
