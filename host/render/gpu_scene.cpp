#include "render/gpu_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "cl/cl_error.h"
#include "scene/texture_lookup.h"

namespace mcrt {

static gpu::float4 to_float4(const glm::vec3& v, float w = 0.0f) { return {v.x, v.y, v.z, w}; }

namespace {

uint32_t wrap_bits(TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::Repeat:
            return TEXTURE_WRAP_REPEAT;
        case TextureWrap::ClampToEdge:
            return TEXTURE_WRAP_CLAMP;
        case TextureWrap::MirroredRepeat:
            return TEXTURE_WRAP_MIRROR;
    }
    return TEXTURE_WRAP_REPEAT;
}

gpu::TextureSlot texture_slot(const TextureRef& ref) {
    gpu::TextureSlot slot{};
    slot.image = ref.used() ? uint32_t(ref.image) : MCRT_NO_TEXTURE;
    slot.m = {ref.row_u.x, ref.row_u.y, ref.row_v.x, ref.row_v.y};
    slot.offset_u = ref.row_u.z;
    slot.offset_v = ref.row_v.z;
    slot.mode = (wrap_bits(ref.wrap_s) << TEXTURE_WRAP_S_SHIFT) |
                (wrap_bits(ref.wrap_t) << TEXTURE_WRAP_T_SHIFT) |
                (ref.linear ? TEXTURE_LINEAR : 0u) | (ref.srgb ? TEXTURE_SRGB : 0u) |
                (ref.texcoord == 1 ? TEXTURE_TEXCOORD_1 : 0u);
    return slot;
}

uint32_t alpha_mode_bits(AlphaMode mode) {
    switch (mode) {
        case AlphaMode::Opaque:
            return MATERIAL_ALPHA_OPAQUE;
        case AlphaMode::Mask:
            return MATERIAL_ALPHA_MASK;
        case AlphaMode::Blend:
            return MATERIAL_ALPHA_BLEND;
    }
    return MATERIAL_ALPHA_OPAQUE;
}

template <typename T>
void append_words(std::vector<uint32_t>& words, const T* items, size_t count) {
    static_assert(sizeof(T) % sizeof(uint32_t) == 0, "whole words");
    const size_t at = words.size();
    words.resize(at + count * sizeof(T) / sizeof(uint32_t));
    if (count) std::memcpy(words.data() + at, items, count * sizeof(T));
}

// RENDER_ARG_TEXTURES (shared_types.h, TextureHeader): the head, the materials' textures, the
// images' table, the decode tables, the texels (RGBA8 per word, red in the low byte: the bytes in
// memory order on a little-endian host, as every OpenCL device here is).
std::vector<uint32_t> texture_words(const Scene& scene) {
    std::vector<gpu::MaterialTextures> materials;
    for (const Material& m : scene.materials) {
        gpu::MaterialTextures t{};
        t.base_color = texture_slot(m.base_color_texture);
        t.metallic_roughness = texture_slot(m.metallic_roughness_texture);
        t.normal = texture_slot(m.normal_texture);
        t.emissive = texture_slot(m.emissive_texture);
        t.transmission = texture_slot(m.transmission_texture);
        t.base_alpha = m.alpha;
        t.alpha_cutoff = m.alpha_cutoff;
        t.normal_scale = m.normal_scale;
        t.alpha_mode = alpha_mode_bits(m.alpha_mode);
        t.roughness = m.roughness;
        // The rotation of T·R·S, from its first column (sx cos r, −sx sin r).
        const glm::vec2 column(m.normal_texture.row_u.x, m.normal_texture.row_v.x);
        const float length = glm::length(column);
        t.normal_cos = length > 0.0f ? column.x / length : 1.0f;
        t.normal_sin = length > 0.0f ? -column.y / length : 0.0f;
        materials.push_back(t);
    }
    if (materials.empty()) materials.push_back(gpu::MaterialTextures{});
    std::vector<gpu::TextureImageGpu> images;
    uint64_t texels = 0;
    for (const TextureImage& image : scene.images) {
        gpu::TextureImageGpu g{};
        g.offset = uint32_t(texels);
        g.width = image.width;
        g.height = image.height;
        images.push_back(g);
        texels += uint64_t(image.width) * image.height;
        if (texels > 0xffffffffu) throw RuntimeError("textures exceed 2^32 texels");
    }
    gpu::TextureHeader head{};
    std::vector<uint32_t> words;
    append_words(words, &head, 1);
    append_words(words, materials.data(), materials.size());
    head.materials = uint32_t(materials.size());
    head.images = uint32_t(words.size());
    append_words(words, images.data(), images.size());
    head.decode = uint32_t(words.size());
    std::array<float, 512> decode{};
    for (int c = 0; c < 256; ++c) {
        decode[size_t(c)] = srgb_table()[size_t(c)];
        decode[256 + size_t(c)] = float(c) / 255.0f;
    }
    append_words(words, decode.data(), decode.size());
    head.texels = uint32_t(words.size());
    for (const TextureImage& image : scene.images) {
        append_words(words, reinterpret_cast<const uint32_t*>(image.rgba.data()),
                     image.rgba.size() / 4);
    }
    std::memcpy(words.data(), &head, sizeof head);
    return words;
}

}  // namespace

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
        // KHR_materials_specular with KHR_materials_ior: the dielectric's F0 = min(f0(ior) ×
        // specularColor, 1) × specular and F90 = specular; GGX α = roughness², at least
        // MCRT_ALPHA_MIN.
        const float alpha = std::max(m.roughness * m.roughness, MCRT_ALPHA_MIN);
        g.base_color = to_float4(m.albedo, 1.0f);
        g.emission = to_float4(m.emission);
        g.specular = to_float4(
            glm::min(dielectric_f0(m.ior) * m.specular_color, glm::vec3(1.0f)) * m.specular,
            m.specular);
        g.metallic = m.metallic;
        g.alpha = alpha;
        g.type = m.lambertian() ? MATERIAL_LAMBERTIAN : MATERIAL_METALLIC_ROUGHNESS;
        g.flags = m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u;
        // KHR_materials_transmission, _ior, _volume (kernels/materials/bsdf.cl, dielectric.cl).
        g.transmission = m.transmission;
        g.ior = m.ior;
        if (m.transmission > 0.0f && m.volume) {
            g.flags |= MATERIAL_VOLUME;
            g.attenuation = to_float4(glm::vec3(volume_attenuation(m)));
        }
        const bool slots = m.base_color_texture.used() || m.metallic_roughness_texture.used() ||
                           m.normal_texture.used() || m.emissive_texture.used() ||
                           m.transmission_texture.used();
        if (slots) g.flags |= MATERIAL_TEXTURED;
        if (m.alpha_mode != AlphaMode::Opaque) g.flags |= MATERIAL_ALPHA_TESTED;
        data.materials.push_back(g);
        data.microfacet = data.microfacet || g.type != MATERIAL_LAMBERTIAN;
        data.transmission = data.transmission || m.transmission > 0.0f;
        data.textured = data.textured || m.textured();
    }
    if (data.materials.empty()) data.materials.push_back(gpu::Material{});

    // Lights in emitter order, selected by power (PBRT 3rd ed. 13.3.1); each triangle records
    // its light so that a direction that hits it can ask the light strategy's density.
    // Each scene triangle's packet lane, for the lights' TriangleSurface.
    std::vector<uint32_t> lane_of_triangle(scene.triangle_count(), MCRT_NO_HIT);
    for (size_t p = 0; p < bvh.packets.size(); ++p) {
        for (int lane = 0; lane < MCRT_PACKET_WIDTH; ++lane) {
            const uint32_t triangle = bvh.packets[p].index[lane];
            if (triangle == MCRT_NO_HIT) continue;
            lane_of_triangle[triangle] = uint32_t(p * MCRT_PACKET_WIDTH) + lane;
        }
    }
    std::vector<EmissiveTriangle> emitters = collect_emitters(scene);
    std::vector<double> powers;
    std::vector<uint32_t> light_of_triangle(scene.triangle_count(), 0);
    for (const EmissiveTriangle& e : emitters) {
        const uint32_t material = scene.triangle_material[e.triangle];
        const Material& m = scene.materials[material];
        const glm::vec3* p = &scene.positions[3 * size_t(e.triangle)];
        gpu::Light light{};
        light.p0 = to_float4(p[0]);
        light.p1 = to_float4(p[1]);
        light.p2 = to_float4(p[2]);
        light.Le = to_float4(m.emission);
        light.area = e.area;
        light.flags = m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u;
        if (m.emissive_texture.used() || m.alpha_mode != AlphaMode::Opaque)
            light.flags |= MATERIAL_TEXTURED;
        light.material = material;
        light.surface = lane_of_triangle[e.triangle];
        data.lights.push_back(light);
        powers.push_back(e.power);
        light_of_triangle[e.triangle] = uint32_t(data.lights.size());
    }
    // Punctual lights after the area lights, by their power (punctual_power: the disk of the
    // scene's bounding sphere for a directional light), in the tree with pbrt-v4's bounds.
    const glm::dvec3 scene_lo(scene.bounds_min()), scene_hi(scene.bounds_max());
    const double radius = scene.triangle_count() > 0 ? 0.5 * glm::length(scene_hi - scene_lo) : 0.0;
    constexpr double kPi = 3.14159265358979323846;
    for (const PunctualLight& l : scene.punctual_lights) {
        gpu::PunctualGpu g{};
        g.position = to_float4(l.position);
        g.direction = to_float4(l.direction);
        g.intensity = to_float4(l.intensity);
        g.spot_scale = l.spot_scale;
        g.spot_offset = l.spot_offset;
        LightTreeItem item;
        const double y = 0.2126 * l.intensity.r + 0.7152 * l.intensity.g + 0.0722 * l.intensity.b;
        item.lo = item.hi = glm::dvec3(l.position);
        item.axis = glm::dvec3(l.direction);
        item.phi = 4.0 * kPi * y;
        switch (l.type) {
            case PunctualType::Point:
                g.type = PUNCTUAL_POINT;
                break;
            case PunctualType::Spot:
                g.type = PUNCTUAL_SPOT;
                // θ_o = inner, θ_e = outer − inner: the falloff is positive for θ < outer, where
                // the importance is too (θ_e at least 10⁻³ rad, so that it is when inner = outer).
                item.cos_o = l.cos_inner;
                item.cos_e = std::cos(std::max(
                    std::acos(double(l.cos_outer)) - std::acos(double(l.cos_inner)), 1e-3));
                break;
            case PunctualType::Directional:
                // The whole scene's box: inside its sphere the importance is 4πr²E / r² = 4πE,
                // as a point light's is 4π × the irradiance it gives.
                g.type = PUNCTUAL_DIRECTIONAL;
                item.lo = scene_lo;
                item.hi = scene_hi;
                item.phi = 4.0 * kPi * radius * radius * y;
                break;
        }
        data.punctual.push_back(g);
        data.punctual_tree_items.push_back(item);
        powers.push_back(punctual_power(l, radius));
    }
    data.light_powers = std::move(powers);
    build_light_selection(data, selection);
    // Shading's view of each packet lane (unused lanes stay zero: no ray hits them).
    data.triangle_info.assign(bvh.packets.size() * MCRT_PACKET_WIDTH, gpu::TriangleInfo{});
    for (size_t p = 0; p < bvh.packets.size(); ++p) {
        for (int lane = 0; lane < MCRT_PACKET_WIDTH; ++lane) {
            const uint32_t scene_triangle = bvh.packets[p].index[lane];
            if (scene_triangle == MCRT_NO_HIT) continue;
            gpu::TriangleInfo& info = data.triangle_info[p * MCRT_PACKET_WIDTH + size_t(lane)];
            info.material = scene.triangle_material[scene_triangle];
            info.light = light_of_triangle[scene_triangle];
            // glTF 2.0 sec. 3.9.2: a single-sided surface is back-face culled, for every ray;
            // never a transmissive one, whose back faces rays inside its volume meet.
            const Material& m = scene.materials[info.material];
            if (!m.double_sided && !(m.transmission > 0.0f)) {
                data.packets[p].index[lane] |= MCRT_TRIANGLE_CULLED;
                data.single_sided = true;
            }
        }
    }
    if (data.textured) {
        // What texture lookups read of each lane's triangle (unused lanes stay zero).
        data.surfaces.assign(bvh.packets.size() * MCRT_PACKET_WIDTH, gpu::TriangleSurface{});
        for (size_t t = 0; t < scene.triangle_count(); ++t) {
            const uint32_t lane = lane_of_triangle[t];
            if (lane == MCRT_NO_HIT) continue;
            gpu::TriangleSurface& s = data.surfaces[lane];
            for (size_t k = 0; k < 3; ++k) {
                const size_t corner = 3 * t + k;
                if (corner < scene.texcoords.size()) {
                    const glm::vec4& uv = scene.texcoords[corner];
                    s.uv[k] = {uv.x, uv.y, uv.z, uv.w};
                }
                if (corner < scene.normals.size()) s.normal[k] = to_float4(scene.normals[corner]);
                if (corner < scene.tangents.size()) {
                    const glm::vec4& tg = scene.tangents[corner];
                    s.tangent[k] = {tg.x, tg.y, tg.z, tg.w};
                }
            }
        }
        data.textures = texture_words(scene);
    }
    data.camera = make_gpu_camera(camera, width, height);
    return data;
}

static LightSelectionInputs light_selection_inputs(const GpuSceneData& data) {
    return {data.lights, data.light_powers, data.punctual_tree_items};
}

void build_light_selection(GpuSceneData& data, LightSelection selection) {
    data.light_selection = build_light_selection(selection, light_selection_inputs(data));
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

// The one place where a scene's selection data meets the selection a render asks for.
static cl::Buffer upload_selection(const DeviceContext& device, const GpuSceneData& data,
                                   LightSelection selection, size_t& bytes, cl_uint* tree_nodes) {
    *tree_nodes = 0;
    if (data.light_selection.selection == selection)
        return upload(device, light_selection_words(data.light_selection, tree_nodes), bytes,
                      "light selection data");
    const LightSelectionData built = build_light_selection(selection, light_selection_inputs(data));
    return upload(device, light_selection_words(built, tree_nodes), bytes, "light selection data");
}

GpuSceneBuffers::GpuSceneBuffers(const DeviceContext& device, const GpuSceneData& data,
                                 LightSelection selection) {
    nodes = upload(device, data.nodes, bytes, "BVH nodes");
    packets = upload(device, data.packets, bytes, "triangle packets");
    triangle_info = upload(device, data.triangle_info, bytes, "triangle materials and lights");
    materials = upload(device, data.materials, bytes, "materials");
    lights = upload(device, data.lights, bytes, "lights");
    light_selection = upload_selection(device, data, selection, bytes, &light_tree_nodes);
    surfaces = upload(device, data.surfaces, bytes, "texture coordinates and tangents");
    textures = upload(device, data.textures, bytes, "textures");
    punctual = upload(device, data.punctual, bytes, "punctual lights");
    camera = upload(device, std::vector<gpu::CameraGpu>{data.camera}, bytes, "camera");
    light_count = cl_uint(data.lights.size());
    punctual_count = cl_uint(data.punctual.size());
}

cl::Buffer upload_light_selection(const DeviceContext& device, const GpuSceneData& data,
                                  LightSelection selection, cl_uint* tree_nodes) {
    size_t bytes = 0;
    return upload_selection(device, data, selection, bytes, tree_nodes);
}

void write_camera(const DeviceContext& device, const GpuSceneBuffers& buffers,
                  const gpu::CameraGpu& camera) {
    CL_CHECK(device.queue.enqueueWriteBuffer(buffers.camera, CL_TRUE, 0, sizeof camera, &camera));
}

}  // namespace mcrt
