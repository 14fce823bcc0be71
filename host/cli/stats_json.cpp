#include "cli/stats_json.h"

#include <array>

#include "render/variants.h"

namespace mcrt {

namespace {

// Bytes of the scene's decoded images (8-bit RGBA).
uint64_t texel_bytes(const Scene& scene) {
    uint64_t bytes = 0;
    for (const TextureImage& image : scene.images) bytes += image.rgba.size();
    return bytes;
}

}  // namespace

nlohmann::json render_stats_json(const RenderStatsInput& in) {
    const RenderOptions& o = in.options;
    const RenderResult& result = in.result;
    const RenderSettings& settings = in.plan.settings;
    const Bvh& bvh = in.scene.bvh;
    const GpuSceneData& gpu_scene = in.scene.gpu;
    uint64_t samples = uint64_t(o.width) * o.height * result.spp;
    const unsigned uses = in.plan.variants.estimator.uses;
    nlohmann::json j = {
        {"scene", o.scene},
        {"width", o.width},
        {"height", o.height},
        {"spp", result.spp},
        {"spp_requested", o.spp},
        {"stopped_by", result.stopped_by},
        {"estimator", o.estimator_file.empty() ? o.estimator : o.estimator_file},
        {"estimator_file", o.estimator_file},
        {"estimator_uses", uses_names(uses)},
        {"light_select", o.light_select},
        {"sampler", o.sampler},
        {"seed", o.seed},
        {"mis_heuristic", o.mis_heuristic},
        {"materials", o.materials},
        {"microfacet", gpu_scene.microfacet},
        {"sky", {settings.sky.r, settings.sky.g, settings.sky.b}},
        {"sky_light", settings.sky_light},
        // The environment map (--env; "" for none) and the probability that the light strategies
        // choose it (RenderPlan::environment_steps).
        {"env", settings.env},
        {"env_scale", settings.env_scale},
        {"env_rotate", settings.env_rotate},
        {"env_light_pmf", double(in.plan.environment_steps) / 16777216.0},
        {"ao_distance", o.ao_distance},
        {"max_depth", settings.max_depth},
        {"rr_depth", settings.rr_depth},
        {"seconds_total", in.seconds_total},
        {"seconds_render", result.seconds_render},
        {"seconds_kernel_build", result.seconds_build},
        // Wall clock from the first launch to the last result: kernels, launch gaps, host work.
        {"seconds_render_wall", result.seconds_render_wall},
        // From the start of the command to the first batch in the image (docs/BENCHMARKS.md,
        // "Start-up").
        {"seconds_to_first_batch", in.seconds_to_render + result.seconds_first_batch},
        {"seconds_bvh_build", bvh.stats.build_seconds},
        {"samples_per_second", result.seconds_render > 0 ? samples / result.seconds_render : 0.0},
        {"rays", result.rays},
        {"rays_per_second", result.seconds_render > 0 ? result.rays / result.seconds_render : 0.0},
        {"rays_per_sample", samples > 0 ? double(result.rays) / samples : 0.0},
        // Surface points per path, the camera's hit included (0 for a ray that misses).
        {"mean_path_length", samples > 0 ? double(result.path_vertices) / samples : 0.0},
        {"roulette_share", samples > 0 ? double(result.roulette_ends) / samples : 0.0},
        {"nan_samples", result.nan_samples},
        {"replicates", result.replicates},
        {"variance_estimate", result.replicates > 1 ? "replicates" : "samples"},
        {"variance_clamped", result.variance_clamped},
        {"nonfinite_pixels", 0},  // run_render writes no image with any
        {"triangles", in.scene.scene.triangle_count()},
        {"lights", gpu_scene.lights.size()},
        {"seconds_scene_load", in.scene.seconds_load},
        // Texture data on each device: texels (4 bytes each) with the materials' slots and the
        // decode tables, and the triangles' texture coordinates and tangents.
        {"textures",
         {{"textured", gpu_scene.textured},
          {"images", in.scene.scene.images.size()},
          {"texel_bytes", texel_bytes(in.scene.scene)},
          {"device_bytes", gpu_scene.textures.size() * sizeof(uint32_t) +
                               gpu_scene.surfaces.size() * sizeof(gpu::TriangleSurface)}}},
        // The 4-wide tree the kernels traverse; the binary SAH tree it collapses as binary_*.
        {"bvh",
         {{"nodes", bvh.nodes4.size()},
          {"packets", bvh.stats.packets},
          {"sah_cost", bvh.stats.sah_cost4},
          {"depth", bvh.stats.depth4},
          {"bytes", bvh.stats.bytes},
          {"binary_nodes", bvh.nodes.size()},
          {"binary_sah_cost", bvh.stats.sah_cost},
          {"binary_depth", bvh.stats.depth},
          {"build_seconds", bvh.stats.build_seconds}}},
    };
    // Image-wide means, so that scripts can compare renders without reading EXR.
    std::array<double, 3> mean{}, mean_variance{};
    size_t pixels = size_t(o.width) * o.height;
    for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
            mean[c] += result.image.rgb[3 * p + c] / double(pixels);
            mean_variance[c] += result.image.variance[3 * p + c] / double(pixels);
        }
    j["image_mean"] = mean;
    j["image_mean_variance"] = mean_variance;
    nlohmann::json devices = nlohmann::json::array();
    for (const DeviceReport& d : result.devices)
        devices.push_back(
            {{"name", d.name},
             {"index", d.index},
             {"samples", d.samples},
             {"batches", d.batches},
             {"seconds_busy", d.seconds_busy},
             {"retired", d.retired},
             {"rank", d.rank},
             {"samples_per_second", d.seconds_busy > 0 ? d.samples / d.seconds_busy : 0.0}});
    j["devices"] = devices;
    return j;
}

}  // namespace mcrt
