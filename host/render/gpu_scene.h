// The scene as the kernels see it: host arrays in the layouts of kernels/core/shared_types.h, and
// their buffers on one device.
#pragma once

#include <CL/opencl.hpp>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "cl/device.h"
#include "lights/light_selection.h"
#include "render/variants.h"
#include "scene/scene.h"
#include "shared_types.h"

namespace mcrt {

struct GpuSceneData {
    std::vector<gpu::Bvh4Node> nodes;              // 4-wide, as the kernels traverse it
    std::vector<gpu::TrianglePacket> packets;      // the leaves' triangles, four per ray test
    std::vector<gpu::TriangleInfo> triangle_info;  // per packet lane: 4 per packet
    std::vector<gpu::Material> materials;
    std::vector<gpu::Light> lights;
    // KHR_lights_punctual lights (RENDER_ARG_PUNCTUAL): the selection's lights after `lights`;
    // a scene with any gets kernels that draw them (-D MCRT_PUNCTUAL), one without none.
    std::vector<gpu::PunctualGpu> punctual;
    std::vector<LightTreeItem> punctual_tree_items;  // their bounds in the light tree
    std::vector<double> light_powers;  // one per light, then per punctual light: what every
                                       // selection is built from
    // The data of one light selection (lights/light_selection.h), as make_gpu_scene was asked.
    LightSelectionData light_selection;
    gpu::CameraGpu camera{};
    // Some material's type is not MATERIAL_LAMBERTIAN: the kernels need that model (-D
    // MCRT_MATERIALS_GLTF); a Lambertian scene's kernels are built without it.
    bool microfacet = false;
    // Some material transmits (Material::transmission > 0): the kernels need the dielectric
    // BTDF and the path's handling of what light strategies cannot reach (-D MCRT_TRANSMISSION).
    bool transmission = false;
    // Some triangle is single-sided and not transmissive: its packet lane carries
    // MCRT_TRIANGLE_CULLED and the kernels cull its back face (-D MCRT_SINGLE_SIDED).
    bool single_sided = false;
    // Some material has a texture or tests alpha (Material::textured): the kernels need texture
    // lookups (-D MCRT_TEXTURES), and these two arrays; an untextured scene leaves them empty.
    bool textured = false;
    std::vector<gpu::TriangleSurface> surfaces;  // per packet lane, as triangle_info
    // TextureHeader, the materials' MaterialTextures, the TextureImageGpu table, the decode
    // tables and the texels, in 32-bit words (RENDER_ARG_TEXTURES).
    std::vector<uint32_t> textures;
};

// The camera of DESIGN.md's camera contract for an image of width × height.
gpu::CameraGpu make_gpu_camera(const Camera& camera, int width, int height);

// Flattens the scene, its BVH and its emitters, with the data of the light selection
// `selection` alone; `camera` as chosen by the caller.
GpuSceneData make_gpu_scene(const Scene& scene, const Bvh& bvh, const Camera& camera, int width,
                            int height, LightSelection selection = LightSelection::Power);

// Replaces the light selection's data with that of `selection`: a scene kept for several
// selections holds one at a time (render/session.h).
void build_light_selection(GpuSceneData& data, LightSelection selection);

// Device copies of GpuSceneData (empty arrays get a one-element buffer, never a null one), with
// the data of light selection `selection` (upload_light_selection).
struct GpuSceneBuffers {
    GpuSceneBuffers(const DeviceContext& device, const GpuSceneData& data,
                    LightSelection selection);
    cl::Buffer nodes, packets, triangle_info, materials, lights, light_selection, surfaces,
        textures, punctual, camera;
    cl_uint light_count = 0;     // area lights
    cl_uint punctual_count = 0;  // punctual lights, chosen after them
    cl_uint light_tree_nodes = 0;
    size_t bytes = 0;
};

// The buffer of light selection `selection` for `data` (RENDER_ARG_LIGHT_SELECTION), `tree_nodes`
// as light_selection_words sets it: the data's own when it holds that selection's, else built
// here, so that a scene built for one selection renders right with another. Every upload of a
// selection goes through here.
cl::Buffer upload_light_selection(const DeviceContext& device, const GpuSceneData& data,
                                  LightSelection selection, cl_uint* tree_nodes);

// Writes the camera of a render into the device scene's camera buffer, waiting for the copy.
void write_camera(const DeviceContext& device, const GpuSceneBuffers& buffers,
                  const gpu::CameraGpu& camera);

}  // namespace mcrt
