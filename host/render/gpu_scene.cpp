#include "render/gpu_scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "cl/cl_error.h"
#include "render/discrete.h"
#include "render/light_tree.h"

namespace mcrt {


static gpu::float4 to_float4(const glm::vec3& v, float w = 0.0f) { return {v.x, v.y, v.z, w}; }

gpu::CameraGpu make_gpu_camera(const Camera& camera, int width, int height) {
    const glm::mat4& m = camera.camera_to_world;
    float tan_half = std::tan(0.5f * camera.yfov);
    float aspect = float(width) / float(height);
    gpu::CameraGpu g{};
    g.eye = to_float4(glm::vec3(m[3]));
    g.right = to_float4(glm::normalize(glm::vec3(m[0])) * (tan_half * aspect));
    g.up = to_float4(glm::normalize(glm::vec3(m[1])) * tan_half);
    g.forward = to_float4(-glm::normalize(glm::vec3(m[2])));
    return g;
}

GpuSceneData make_gpu_scene(const Scene& scene, const Bvh& bvh, const Camera& camera, int width,
                            int height, LightSelection selection) {
    GpuSceneData data;
    data.nodes = bvh.nodes4;
    data.packets = bvh.packets;
    for (const Material& m : scene.materials) {
        gpu::Material g{};
        // KHR_materials_specular: the dielectric's F0 = min(0.04 specularColor, 1) × specular
        // and F90 = specular; GGX α = roughness², at least MCRT_ALPHA_MIN.
        const float alpha = std::max(m.roughness * m.roughness, MCRT_ALPHA_MIN);
        g.base_color = to_float4(m.albedo, 1.0f);
        g.emission = to_float4(m.emission);
        g.specular = to_float4(glm::min(0.04f * m.specular_color, glm::vec3(1.0f)) * m.specular,
                               m.specular);
        g.metallic = m.metallic;
        g.alpha = alpha;
        g.type = m.lambertian() ? MATERIAL_LAMBERTIAN : MATERIAL_METALLIC_ROUGHNESS;
        g.flags = m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u;
        data.materials.push_back(g);
        data.microfacet = data.microfacet || g.type != MATERIAL_LAMBERTIAN;
    }
    if (data.materials.empty()) data.materials.push_back(gpu::Material{});

    // Lights in emitter order, selected by power (PBRT 3rd ed. 13.3.1); each triangle records
    // its light so that a direction that hits it can ask the light strategy's density.
    std::vector<EmissiveTriangle> emitters = collect_emitters(scene);
    std::vector<double> powers;
    std::vector<uint32_t> light_of_triangle(scene.triangle_count(), 0);
    for (const EmissiveTriangle& e : emitters) {
        const Material& m = scene.materials[scene.triangle_material[e.triangle]];
        const glm::vec3* p = &scene.positions[3 * size_t(e.triangle)];
        gpu::Light light{};
        light.p0 = to_float4(p[0]);
        light.p1 = to_float4(p[1]);
        light.p2 = to_float4(p[2]);
        light.Le = to_float4(m.emission);
        light.area = e.area;
        light.flags = m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u;
        data.lights.push_back(light);
        powers.push_back(e.power);
        light_of_triangle[e.triangle] = uint32_t(data.lights.size());
    }
    data.light_powers = std::move(powers);
    build_light_selection(data, selection);
    // Shading's view of each packet lane (unused lanes stay zero: no ray hits them).
    data.triangle_info.assign(bvh.packets.size() * MCRT_PACKET_WIDTH, gpu::TriangleInfo{});
    for (size_t p = 0; p < bvh.packets.size(); ++p) {
        for (int lane = 0; lane < MCRT_PACKET_WIDTH; ++lane) {
            const uint32_t leaf = bvh.packets[p].index[lane];
            if (leaf == MCRT_NO_HIT) continue;
            const uint32_t scene_triangle = bvh.triangles[leaf].index;
            gpu::TriangleInfo& info = data.triangle_info[p * MCRT_PACKET_WIDTH + size_t(lane)];
            info.material = scene.triangle_material[scene_triangle];
            info.light = light_of_triangle[scene_triangle];
        }
    }
    data.camera = make_gpu_camera(camera, width, height);
    return data;
}

void build_light_selection(GpuSceneData& data, LightSelection selection) {
    data.light_selection = selection;
    data.light_cdf.clear();
    data.light_alias.clear();
    data.light_tree = LightTree{};
    const std::vector<double>& powers = data.light_powers;
    switch (selection) {
        case LightSelection::Uniform: break;
        case LightSelection::Power: data.light_cdf = build_cdf(powers); break;
        case LightSelection::Alias: data.light_alias = build_alias_table(powers); break;
        case LightSelection::Tree: data.light_tree = build_light_tree(data.lights, powers); break;
    }
}

std::vector<uint32_t> light_selection_words(const GpuSceneData& data, uint32_t* tree_nodes) {
    *tree_nodes = 0;
    auto words = [](const auto& items) {
        std::vector<uint32_t> w(items.size() * sizeof(items[0]) / sizeof(uint32_t));
        if (!items.empty()) std::memcpy(w.data(), items.data(), w.size() * sizeof(uint32_t));
        return w;
    };
    switch (data.light_selection) {
        case LightSelection::Uniform: return {};
        case LightSelection::Power: return words(data.light_cdf);
        case LightSelection::Alias: return words(data.light_alias);
        case LightSelection::Tree:
            *tree_nodes = uint32_t(std::max<size_t>(data.light_tree.nodes.size(), 1));
            return light_tree_words(data.light_tree);
    }
    return {};
}

template <typename T>
static cl::Buffer upload(const DeviceContext& device, const std::vector<T>& items, size_t& bytes,
                         const char* what) {
    std::vector<T> padded = items.empty() ? std::vector<T>(1) : std::vector<T>();
    const std::vector<T>& source = items.empty() ? padded : items;
    size_t size = source.size() * sizeof(T);
    if (size > device.info.max_allocation)
        throw RuntimeError(std::string("scene ") + what + " need " + std::to_string(size) +
                           " bytes, more than the " + std::to_string(device.info.max_allocation) +
                           " bytes device '" + device.info.name + "' can allocate at once");
    cl_int status = CL_SUCCESS;
    cl::Buffer buffer(device.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, size,
                      const_cast<T*>(source.data()), &status);
    CL_CHECK_STATUS(status, (std::string("clCreateBuffer(") + what + ")").c_str());
    bytes += size;
    return buffer;
}

GpuSceneBuffers::GpuSceneBuffers(const DeviceContext& device, const GpuSceneData& data) {
    nodes = upload(device, data.nodes, bytes, "BVH nodes");
    packets = upload(device, data.packets, bytes, "triangle packets");
    triangle_info = upload(device, data.triangle_info, bytes, "triangle materials and lights");
    materials = upload(device, data.materials, bytes, "materials");
    lights = upload(device, data.lights, bytes, "lights");
    light_selection = upload(device, light_selection_words(data, &light_tree_nodes), bytes,
                             "light selection data");
    camera = upload(device, std::vector<gpu::CameraGpu>{data.camera}, bytes, "camera");
    light_count = cl_uint(data.lights.size());
}

}  // namespace mcrt
