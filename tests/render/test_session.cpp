// The render session (render/session.h): a scene loaded once and rendered under several
// requests gives, request by request, the bytes of a render planned and uploaded afresh
// (plan_render + render()), and releases a scene's device buffers once nobody holds the scene;
// the workers it hands to another process's driver (serve) render what fresh workers render.
#include <catch2/catch.hpp>
#include <cstring>

#include "common/error.h"
#include "device_support.h"
#include "render/device_worker.h"
#include "render/plan.h"
#include "render/renderer.h"
#include "render/session.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

RenderRequest request(const char* estimator, const char* light_select, const char* sampler) {
    RenderRequest r;
    r.scene = kCornell;
    r.settings.width = 20;
    r.settings.height = 12;
    r.settings.spp = 16;
    r.settings.seed = 5;
    r.settings.max_depth = 3;
    r.settings.estimator = estimator;
    r.settings.light_select = light_select;
    r.settings.sampler = sampler;
    return r;
}

bool same_bytes(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height && a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0 &&
           std::memcmp(a.variance.data(), b.variance.data(), a.variance.size() * sizeof(float)) ==
               0;
}

// The render of `r` as a process of one render makes it: planned, laid out and uploaded afresh.
RenderResult fresh_render(const DeviceContext& device, const RenderRequest& r) {
    const PlannedRender planned = plan_render(r, SceneSource{}, {});
    return render(std::vector<const DeviceContext*>{&device}, planned.scene.gpu, planned.plan);
}

}  // namespace

TEST_CASE("a session renders one loaded scene under many requests, each as a fresh render",
          "[session]") {
    std::vector<DeviceInfo> devices = enumerate_devices({});
    REQUIRE(!devices.empty());
    RenderSession session({devices.front()});
    const DeviceContext& device = *session.devices().front();
    auto scene = load_session_scene(kCornell, "gltf", LightSelection::Power, SceneSource{}, {});

    std::vector<RenderRequest> requests = {
        request("mis", "power", "independent"), request("mis", "tree", "sobol"),
        request("light-area", "alias", "stratified"), request("bsdf", "uniform", "independent"),
        request("mis", "power", "independent")};  // the first light selection's buffer again
    RenderRequest look = request("light-solid-angle", "tree", "sobol");
    look.camera.look = Camera{};  // at (0, 1, 3.5) looking down -z, narrower than the scene's
    look.camera.look->camera_to_world[3] = glm::vec4(0.0f, 1.0f, 3.5f, 1.0f);
    look.camera.look->yfov = 0.6f;
    requests.push_back(look);
    requests.push_back(request("mis", "power", "independent"));  // the scene's camera again
    for (const RenderRequest& r : requests) {
        INFO(r.settings.estimator << " " << r.settings.light_select << " " << r.settings.sampler);
        const RenderPlan plan = plan_session_render(*scene, r, {});
        const RenderResult kept = session.render(scene, plan);
        CHECK(kept.spp == 16);
        CHECK(same_bytes(kept.image, fresh_render(device, r).image));
    }
    CHECK(session.uploaded_scenes() == 1);
    // The last render's selection (power) was on the device already: the host still holds the
    // data of the last one it built (uniform's, which has none to build), not power's again.
    CHECK(scene->prepared.gpu.light_selection.selection == LightSelection::Uniform);

    // A scene nobody holds loses its buffers at the next render.
    auto other = load_session_scene(kCornell, "lambert", LightSelection::Power, SceneSource{}, {});
    scene.reset();
    RenderRequest lambert = request("mis", "power", "independent");
    lambert.settings.materials = "lambert";
    session.render(other, plan_session_render(*other, lambert, {}));
    CHECK(session.uploaded_scenes() == 1);
}

TEST_CASE("a session scene refuses a request for other materials than it was loaded with",
          "[session]") {
    auto scene = load_session_scene(kCornell, "lambert", LightSelection::Power, SceneSource{}, {});
    CHECK_THROWS_AS(plan_session_render(*scene, request("mis", "power", "independent"), {}),
                    SettingError);
    CHECK_THROWS_AS(
        load_session_scene(kCornell, "plastic", LightSelection::Power, SceneSource{}, {}),
        SettingError);
}

TEST_CASE("the workers a session serves with render an item's sums as a freshly uploaded worker",
          "[session]") {
    std::vector<DeviceInfo> devices = enumerate_devices({});
    REQUIRE(!devices.empty());
    RenderSession session({devices.front()});
    const DeviceContext& device = *session.devices().front();
    auto scene = load_session_scene(kCornell, "gltf", LightSelection::Power, SceneSource{}, {});
    RenderRequest r = request("mis", "tree", "sobol");
    r.settings.spp = 2 * MCRT_SAMPLES_PER_CHUNK;  // two chunks a pixel
    const RenderPlan plan = plan_session_render(*scene, r, {});
    const PlannedRender planned = plan_render(r, SceneSource{}, {});

    // Two items of the image, as rank 0 hands them out: every pixel's first chunk, then the
    // second chunk of the image's second half (a worker renders any item in any order).
    const uint32_t pixels = uint32_t(r.settings.width * r.settings.height);
    WorkItem first{0, 0, 1, 0, pixels}, second{1, 1, 2, pixels / 2, pixels};
    auto sums_of = [](RenderWorker& w, const WorkItem& item) {
        BatchResult b = w.run(item);
        CHECK(b.item.seq == item.seq);
        return b.sums;
    };
    DeviceWorker fresh(device, planned.scene.gpu, planned.plan);
    const std::vector<gpu::ChunkSums> want_first = sums_of(fresh, first),
                                      want_second = sums_of(fresh, second);
    REQUIRE(!want_first.empty());
    auto same = [](const std::vector<gpu::ChunkSums>& a, const std::vector<gpu::ChunkSums>& b) {
        return a.size() == b.size() &&
               std::memcmp(a.data(), b.data(), a.size() * sizeof(gpu::ChunkSums)) == 0;
    };

    for (int pass = 0; pass < 2; ++pass) {  // the second on the buffers the first uploaded
        INFO("pass " << pass);
        size_t served = 0;
        session.serve(scene, plan, [&](std::vector<std::unique_ptr<DeviceWorker>>& workers) {
            served = workers.size();
            REQUIRE(workers.size() == 1);
            CHECK(same(sums_of(*workers[0], second), want_second));
            CHECK(same(sums_of(*workers[0], first), want_first));
        });
        CHECK(served == 1);
        CHECK(session.uploaded_scenes() == 1);
    }
    // The session renders afterwards as before.
    CHECK(same_bytes(session.render(scene, plan).image, fresh_render(device, r).image));
}
