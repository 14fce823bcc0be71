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
                            int height, bool light_tree) {
    GpuSceneData data;
    data.nodes = bvh.nodes4;
    data.packets = bvh.packets;
    for (const Material& m : scene.materials) {
        gpu::Material g{};
        // KHR_materials_specular: the dielectric's F0 = min(0.04 specularColor, 1) × specular
        // and F90 = specular; GGX α = roughness², at least MCRT_ALPHA_MIN.
        const float alpha = std::max(m.roughness * m.roughness, MCRT_ALPHA_MIN);
        g.albedo = to_float4(m.albedo, m.metallic);
        g.Le = to_float4(m.emission, alpha);
        g.specular = to_float4(glm::min(0.04f * m.specular_color, glm::vec3(1.0f)) * m.specular,
                               m.specular);
        g.flags = m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u;
        data.materials.push_back(g);
        data.microfacet = data.microfacet || !m.lambertian();
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
        light.p0 = to_float4(p[0], e.area);
        light.p1 = to_float4(p[1], gpu::as_float(m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u));
        light.p2 = to_float4(p[2]);
        light.Le = to_float4(m.emission);
        data.lights.push_back(light);
        powers.push_back(e.power);
        light_of_triangle[e.triangle] = uint32_t(data.lights.size());
    }
    data.light_cdf = build_cdf(powers);
    data.light_alias = build_alias_table(powers);
    if (light_tree) {
        LightTree tree = build_light_tree(data.lights, powers);
        store_light_trails(tree, data.lights);
        data.light_tree = std::move(tree.nodes);
    }
    // Shading's view of each packet lane (unused lanes stay zero: no ray hits them).
    data.triangle_info.assign(bvh.packets.size() * MCRT_PACKET_WIDTH, gpu::TriangleInfo{});
    for (size_t p = 0; p < bvh.packets.size(); ++p) {
        for (int lane = 0; lane < MCRT_PACKET_WIDTH; ++lane) {
            const uint32_t leaf = bvh.packets[p].index[lane];
            if (leaf == MCRT_NO_HIT) continue;
            const uint32_t scene_triangle = gpu::as_uint(bvh.triangles[leaf].p1.w);
            gpu::TriangleInfo& info = data.triangle_info[p * MCRT_PACKET_WIDTH + size_t(lane)];
            info.material = scene.triangle_material[scene_triangle];
            info.light = light_of_triangle[scene_triangle];
        }
    }
    data.camera = make_gpu_camera(camera, width, height);
    return data;
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
    light_cdf = upload(device, data.light_cdf, bytes, "light CDF");
    light_alias = upload(device, data.light_alias, bytes, "light alias table");
    light_tree = upload(device, data.light_tree, bytes, "light tree");
    camera = upload(device, std::vector<gpu::CameraGpu>{data.camera}, bytes, "camera");
    light_count = cl_uint(data.lights.size());
}

}  // namespace mcrt
