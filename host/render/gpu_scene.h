// The scene as the kernels see it: host arrays in the layouts of kernels/shared_types.h, and
// their buffers on one device.
#pragma once

#include <string>
#include <vector>

#include <CL/opencl.hpp>

#include "bvh/bvh.h"
#include "cl/device.h"
#include "scene/scene.h"
#include "shared_types.h"

namespace mcrt {

struct GpuSceneData {
    std::vector<gpu::Bvh4Node> nodes;  // 4-wide, as the kernels traverse it
    std::vector<gpu::TrianglePacket> packets;  // the leaves' triangles, four per ray test
    std::vector<gpu::TriangleInfo> triangle_info;  // per packet lane: 4 per packet
    std::vector<gpu::Material> materials;
    std::vector<gpu::Light> lights;
    std::vector<float> light_cdf;  // lights + 1 entries, by power (PBRT 3rd ed. 13.3.1)
    std::vector<gpu::AliasEntry> light_alias;  // the same distribution as an alias table
    std::vector<gpu::LightTreeNode> light_tree;  // --light-select tree (render/light_tree.h)
    gpu::CameraGpu camera{};
    // Some surface is not Lambertian: the kernels need the microfacet BRDF (-D
    // MCRT_MATERIALS_GLTF); a Lambertian scene's kernels are built without it.
    bool microfacet = false;
};

// The camera of DESIGN.md's camera contract for an image of width × height.
gpu::CameraGpu make_gpu_camera(const Camera& camera, int width, int height);

// Flattens the scene, its BVH and its emitters; `camera` as chosen by the caller. The light
// tree is built only with `light_tree` (the other selections never read it: it costs about
// 128 bytes per light).
GpuSceneData make_gpu_scene(const Scene& scene, const Bvh& bvh, const Camera& camera, int width,
                            int height, bool light_tree = true);

// Device copies of GpuSceneData (empty arrays get a one-element buffer, never a null one).
struct GpuSceneBuffers {
    GpuSceneBuffers(const DeviceContext& device, const GpuSceneData& data);
    cl::Buffer nodes, packets, triangle_info, materials, lights, light_cdf, light_alias, light_tree,
        camera;
    cl_uint light_count = 0;
    size_t bytes = 0;
};

}  // namespace mcrt
