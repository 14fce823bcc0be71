#include "render/plan.h"

#include <chrono>
#include <cmath>

#include "common/activity.h"
#include "common/error.h"

namespace mcrt {

namespace {

// Replicates for `requested` (0: the default of the variants) with `spp` samples per pixel: a
// power of two dividing 16 and spp.
uint32_t replicates_for(uint32_t requested, uint32_t spp, const RenderVariants& variants) {
    if (requested > 0) {
        if (MCRT_SAMPLES_PER_CHUNK % requested != 0 || spp % requested != 0)
            throw SettingError("replicates", std::to_string(requested) +
                                                 ": expected 1, 2, 4, 8 or 16, dividing spp " +
                                                 std::to_string(spp));
        return requested;
    }
    if (!variants.correlated()) return 1;  // independent samples: their own variance is honest
    uint32_t k = kDefaultReplicates;
    while (spp % k != 0) k /= 2;  // the largest power of two up to it dividing spp
    return k;
}

}  // namespace

uint32_t resolve_replicates(uint32_t requested, const RenderSettings& settings) {
    return replicates_for(requested, settings.spp, resolve_variants(settings));
}

RenderPlan check_render_settings(RenderSettings settings, const std::optional<glm::vec3>& sky) {
    RenderPlan plan;
    plan.variants = resolve_variants(settings);
    const RenderVariants& v = plan.variants;
    if (settings.max_depth > MCRT_MAX_PATH_DEPTH)
        throw SettingError("max_depth", std::to_string(settings.max_depth) + ": at most " +
                                            std::to_string(MCRT_MAX_PATH_DEPTH));
    if (settings.rr_depth < 1 || settings.rr_depth > MCRT_MAX_PATH_DEPTH)
        throw SettingError("rr_depth", std::to_string(settings.rr_depth) + ": expected 1 .. " +
                                           std::to_string(MCRT_MAX_PATH_DEPTH));
    // The ambient estimators integrate sky visibility, not reflected light: no path to extend.
    if (v.ambient() && settings.max_depth > 1)
        throw SettingError(
            "max_depth",
            std::to_string(settings.max_depth) + ": estimator " + v.estimator.name +
                " is an ambient estimator (sky visibility, one bounce): max_depth 0 or 1; path "
                "tracing under the sky is a sky light with light-area, light-solid-angle, bsdf, "
                "hemisphere-* or mis");
    // The ambient estimators' sky is 1 unless given; for the others a sky makes it a light.
    // An environment map takes the sky's place (plan_environment).
    if (!settings.env.empty()) {
        if (sky)
            throw SettingError("env",
                               settings.env + ": --env and --sky both give the sky; give one");
        if (!std::isfinite(settings.env_scale) || settings.env_scale < 0.0f)
            throw SettingError("env_scale", std::to_string(settings.env_scale) +
                                                ": expected a finite number >= 0");
        if (!std::isfinite(settings.env_rotate))
            throw SettingError("env_rotate", "expected a finite number of degrees");
        settings.sky = glm::vec3(v.ambient() ? 1.0f : 0.0f);
        settings.sky_light = v.uses(kUsesSkyLight);
    } else if (sky) {
        settings.sky = *sky;
        settings.sky_light = v.uses(kUsesSkyLight) && (sky->r > 0 || sky->g > 0 || sky->b > 0);
    } else {
        settings.sky = glm::vec3(v.ambient() ? 1.0f : 0.0f);
        settings.sky_light = false;
    }
    settings.replicates = replicates_for(settings.replicates, settings.spp, v);
    plan.settings = std::move(settings);
    return plan;
}

void plan_environment(RenderPlan& plan, const GpuSceneData& scene, const SceneSource& source) {
    const RenderSettings& s = plan.settings;
    plan.environment = nullptr;
    plan.environment_steps = 0;
    if (s.env.empty()) return;
    {
        const Activity activity("loading the environment map");
        plan.environment =
            load_environment_light(s.env, s.env_scale, s.env_rotate, source.bundle, source.record);
    }
    if (s.sky_light)
        plan.environment_steps =
            environment_pmf_steps(*plan.environment, scene, plan.variants.light_select->id);
}

RenderPlan finish_render_plan(RenderPlan plan, const GpuSceneData& scene) {
    const RenderSettings& s = plan.settings;
    plan.program_options = variant_program_options(
        plan.variants, scene.microfacet, scene.textured, scene.transmission, scene.single_sided,
        plan.environment != nullptr, !scene.punctual.empty());
    plan.fixed_batch = s.batch > 0 ? uint64_t(s.width) * uint64_t(s.height) *
                                         batch_samples_per_pixel(s.batch, s.width, s.height, s.spp)
                                   : 0;
    return plan;
}

RenderPlan make_render_plan(const RenderSettings& settings, const GpuSceneData& scene) {
    const bool env = !settings.env.empty();
    RenderPlan plan =
        check_render_settings(settings, env ? std::nullopt : std::optional(settings.sky));
    if (!env) {  // the sky as the caller of a device scene chose it
        plan.settings.sky = settings.sky;
        plan.settings.sky_light = settings.sky_light;
    }
    plan_environment(plan, scene, SceneSource{});
    return finish_render_plan(std::move(plan), scene);
}

void warn_unseen_lights(const std::string& scene_path, const RenderPlan& plan,
                        const GpuSceneData& scene, const WarningSink& warn) {
    if (!warn) return;
    const RenderVariants& v = plan.variants;
    const RenderSettings& s = plan.settings;
    const size_t punctual = scene.punctual.size();
    const bool sees_punctual = v.uses(kUsesLightSelection);
    // One warning at most: the punctual lights' where the estimator cannot see them.
    if (v.uses(kUsesLights) && !s.sky_light && scene.lights.empty() && punctual == 0)
        warn(scene_path + ": no emissive triangles: direct lighting is black" +
             (v.uses(kUsesSkyLight) ? " (--sky R,G,B adds a sky light)" : ""));
    if (punctual > 0 && !sees_punctual)
        warn(scene_path + ": estimator " + v.estimator.name + " cannot see the scene's " +
             std::to_string(punctual) + " KHR_lights_punctual light" + (punctual == 1 ? "" : "s") +
             " (delta lights: no direction it draws finds one); light-area, light-solid-angle "
             "and mis sample them");
}

Camera choose_camera(const Scene& scene, const CameraChoice& choice) {
    if (choice.look) return *choice.look;
    if (choice.index >= 0) {
        // K names glTF `cameras[K]`, seen from its first node in default-scene traversal order.
        const size_t count = scene.gltf_camera_types.size();
        const std::string k = std::to_string(choice.index);
        if (size_t(choice.index) >= count)
            throw SettingError("camera",
                               k + ": " + scene.path + " has " + std::to_string(count) +
                                   (count == 1 ? " camera" : " cameras") +
                                   (count ? " (0 to " + std::to_string(count - 1) + ")" : ""));
        const std::string& type = scene.gltf_camera_types[size_t(choice.index)];
        if (type != "perspective")
            throw SettingError("camera", k + ": camera " + k + " of " + scene.path + " is " + type +
                                             "; only perspective cameras are rendered");
        for (const Camera& camera : scene.cameras)
            if (camera.gltf_index == choice.index) return camera;
        throw SettingError("camera", k + ": camera " + k + " of " + scene.path +
                                         " is on no node of the default scene");
    }
    return scene.cameras.empty() ? bench_camera(scene) : scene.cameras.front();
}

Scene read_scene(const std::string& path, const SceneSource& source, const WarningSink& warn) {
    if (source.bundle) return load_gltf_from_bundle(path, *source.bundle, warn);
    return load_gltf(path, warn, source.files_read, source.record);
}

PlannedRender plan_render(const RenderRequest& request, const SceneSource& source,
                          const WarningSink& warn) {
    PlannedRender r;
    r.plan = check_render_settings(request.settings, request.sky);
    const RenderVariants& v = r.plan.variants;
    const RenderSettings& s = r.plan.settings;
    const auto load_start = std::chrono::steady_clock::now();
    {
        const Activity activity("loading the scene");
        r.scene.scene = read_scene(request.scene, source, warn);
    }
    r.scene.seconds_load =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    Scene& scene = r.scene.scene;
    if (v.materials->lambertian) make_lambertian(scene.materials);
    r.scene.camera = choose_camera(scene, request.camera);
    {
        const Activity activity("building the BVH");
        r.scene.bvh = build_bvh(scene);
    }
    {
        const Activity activity("laying out the scene for the devices");
        r.scene.gpu = make_gpu_scene(scene, r.scene.bvh, r.scene.camera, s.width, s.height,
                                     v.light_select->id);
    }
    if (warn && scene.triangle_count() == 0) warn(request.scene + ": the scene has no triangles");
    warn_unseen_lights(request.scene, r.plan, r.scene.gpu, warn);
    plan_environment(r.plan, r.scene.gpu, source);
    r.plan = finish_render_plan(std::move(r.plan), r.scene.gpu);
    return r;
}

}  // namespace mcrt
