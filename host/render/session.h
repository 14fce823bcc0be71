// A render session: the devices, and what every render of a loaded scene shares, kept from one
// render to the next. A scene is read, its BVH built and laid out for the devices once
// (load_session_scene); a render of it plans its request (plan_session_render: the settings
// checked, the camera chosen) and runs on the session's devices, where the scene's buffers are
// uploaded at its first render and each light selection's data built and uploaded at the first
// render that uses it. Compiled programs are kept per process
// (cl/program.h, cached_program). The command line renders through a session of one request;
// the Python module (python/) keeps one per mcrt.Context.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "cl/device.h"
#include "render/device_worker.h"
#include "render/plan.h"
#include "render/renderer.h"

namespace mcrt {

// A scene as loaded for a session's renders: read, its materials read as the materials variant
// says, its BVH built and laid out for the devices.
struct SessionScene {
    std::string path;
    std::string materials;  // a row of kMaterialVariants
    // The camera is the scene's default (choose_camera) until a plan chooses one; the device
    // layout holds the data of the light selection last uploaded.
    PreparedScene prepared;
    uint64_t id = 0;  // unique in the process: what a session's uploads are kept under
    // Held by a caller that plans and renders the scene from several threads (the Python
    // module): a plan changes the camera, a render the light selection's data.
    std::mutex use;
};

// Reads `path` from `source` for renders with the materials variant `materials`; the device
// layout is made for the light selection `selection`. Throws InputError for a scene that cannot
// be read, SettingError for materials that name no variant; warnings of the import go to `warn`.
std::shared_ptr<SessionScene> load_session_scene(const std::string& path,
                                                 const std::string& materials,
                                                 LightSelection selection,
                                                 const SceneSource& source,
                                                 const WarningSink& warn);

// Environment maps read for a session's renders, each kept while its file is unchanged: renders
// under one map read and sample it once. A file is known by its path, device, inode, size and
// modification time (stat), so a map rewritten between renders is read again.
class EnvironmentCache {
  public:
    // The map of `path` × scale, turned by rotate_deg, as load_environment_light reads it from
    // the disk (its InputError for a file it cannot read): the one kept when the file and the
    // values are those it was read with.
    std::shared_ptr<const EnvironmentLight> load(const std::string& path, float scale,
                                                 float rotate_deg);

    uint64_t reads() const;  // maps read from the disk so far (tests)

  private:
    struct FileIdentity {
        uint64_t device = 0, inode = 0, size = 0;
        int64_t mtime_ns = 0;
        bool operator==(const FileIdentity& o) const {
            return device == o.device && inode == o.inode && size == o.size &&
                   mtime_ns == o.mtime_ns;
        }
    };
    static std::optional<FileIdentity> identify(const std::string& path);
    struct Entry {
        FileIdentity file;
        float scale = 1.0f, rotate_deg = 0.0f;
        std::shared_ptr<const EnvironmentLight> light;
        uint64_t last_use = 0;
    };
    static constexpr size_t kMaxMaps = 4;  // a map of 8k x 4k texels holds 0.8 GB
    std::map<std::string, Entry> maps_;    // by path: the last map read from it
    uint64_t uses_ = 0, reads_ = 0;
    mutable std::mutex mutex_;
};

// The plan of `request` for the loaded scene, as plan_render makes it: the settings checked
// (SettingError), the camera chosen (SettingError) into scene.prepared.camera, the warnings of
// plan_render (no triangles, no lights for an estimator that needs them). The request's
// materials must be the scene's.
// The environment map (--env) is read from `source` (the disk unless a bundle is given), or
// taken from `environments` when given, for a map read from the disk and not recorded.
RenderPlan plan_session_render(SessionScene& scene, const RenderRequest& request,
                               const WarningSink& warn, const SceneSource& source = {},
                               EnvironmentCache* environments = nullptr);

// The process's one context and in-order queue on the device, made at the first call. Sessions
// share them: cached_program keeps each program built for a context for the life of the process,
// so a context per session would build every variant again, and keep it, for each new session.
std::shared_ptr<DeviceContext> process_device_context(const DeviceInfo& device);

class RenderSession {
  public:
    // Renders on the devices, in the order given, through the process's context and queue of
    // each (process_device_context). With more than one device, one whose context or queue
    // cannot be made is skipped with a warning through `warn`; the error is thrown when no
    // device is left (or for the only one).
    explicit RenderSession(const std::vector<DeviceInfo>& devices, const WarningSink& warn = {});
    RenderSession(const RenderSession&) = delete;
    RenderSession& operator=(const RenderSession&) = delete;

    const std::vector<const DeviceContext*>& devices() const { return device_list_; }

    // Renders the plan (plan_session_render of the same scene, the last one made) as render()
    // does, on the scene's buffers kept on each device: uploaded at the scene's first render on
    // the session, the light selection's at its first. One render at a time; the uploads of
    // scenes no longer held elsewhere are released at the next render.
    RenderResult render(const std::shared_ptr<SessionScene>& scene, const RenderPlan& plan,
                        const ProgressSink& progress = {}, const RenderControl& control = {},
                        const WarningSink& warn = {}, const RemoteWorkers& remote = {});

    // The workers of a render that another process drives (an MPI rank serving rank 0's work
    // items, host/mpi/job.h): set up on the scene's buffers kept on each device as render() sets
    // up its own, one per device; a device that cannot render is skipped with a warning through
    // `warn`. `serve` runs with them while the session renders nothing else.
    using Serve = std::function<void(std::vector<std::unique_ptr<DeviceWorker>>& workers)>;
    void serve(const std::shared_ptr<SessionScene>& scene, const RenderPlan& plan,
               const Serve& serve, const WarningSink& warn = {});

    // The environment maps of the session's renders (plan_session_render).
    EnvironmentCache& environments() { return environments_; }

    // Scenes whose buffers are on the devices now (tests: a released scene's are freed).
    size_t uploaded_scenes() const;
    // Environment maps uploaded to a device so far (tests: a map the devices hold is not
    // uploaded again).
    uint64_t environment_uploads() const;

  private:
    // One scene on one device: its buffers, with the light selection's buffer of each selection
    // rendered so far.
    struct DeviceUpload {
        std::unique_ptr<GpuSceneBuffers> buffers;
        struct Selection {
            cl::Buffer buffer;
            cl_uint tree_nodes = 0;
        };
        std::map<LightSelection, Selection> selections;
    };
    struct SceneUploads {
        std::weak_ptr<SessionScene> scene;
        std::map<int, DeviceUpload> devices;  // by device index
    };

    // The scene's uploads, those of scenes nobody holds any more released first. Holds mutex_.
    SceneUploads& uploads_of(const std::shared_ptr<SessionScene>& scene);
    // A worker on `device` for the plan, on the scene's buffers there (uploaded at the first).
    // Holds mutex_.
    std::unique_ptr<DeviceWorker> make_worker(SceneUploads& uploads, SessionScene& scene,
                                              const RenderPlan& plan, const DeviceContext& device);

    std::vector<std::shared_ptr<DeviceContext>> contexts_;
    EnvironmentCache environments_;
    std::vector<const DeviceContext*> device_list_;
    std::map<uint64_t, SceneUploads> uploads_;  // by SessionScene::id
    // The environment map of the last render under one, on each device (by device index): a
    // sweep under one map uploads it once.
    struct EnvironmentUpload {
        std::shared_ptr<const EnvironmentLight> light;
        cl::Buffer buffer;
    };
    std::map<int, EnvironmentUpload> environment_uploads_;
    uint64_t environment_upload_count_ = 0;
    mutable std::mutex mutex_;
};

}  // namespace mcrt
