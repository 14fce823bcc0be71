// The minimal scene model: triangles, materials, camera — nothing else (DESIGN.md "Data flow").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <string>
#include <vector>

#include "scene/punctual_light.h"

namespace mcrt {

// How a texture's coordinates outside [0, 1] are read, per axis (glTF 2.0 "Samplers"; default
// REPEAT).
enum class TextureWrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

// A decoded glTF image: 8-bit RGBA texels as the file stores them (sRGB-encoded or linear: the
// slot that reads it says which), row 0 the image's top row, where texture coordinate v = 0 lies
// (glTF 2.0 "Images"). Grey, grey+alpha and RGB images are widened (alpha 255 when absent).
struct TextureImage {
    std::string name;  // its uri or "image N"
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba;  // width × height × 4 bytes, row by row
};

// One texture slot of a material (glTF 2.0 "textureInfo" with its texture's sampler and
// KHR_texture_transform): which image, how it is read, with which texture coordinates.
struct TextureRef {
    int32_t image = -1;  // index into Scene::images; −1: the slot is empty
    bool srgb = false;   // baseColor and emissive hold sRGB-encoded values; others linear
    TextureWrap wrap_s = TextureWrap::Repeat, wrap_t = TextureWrap::Repeat;
    bool linear = true;     // the sampler's magFilter: LINEAR (default) or NEAREST
    uint32_t texcoord = 0;  // TEXCOORD_n, 0 or 1 (KHR_texture_transform's texCoord applied)
    // KHR_texture_transform: (u', v') = M (u, v, 1), M = T(offset) R(rotation) S(scale); rows
    // [0] and [1] of the 2×3 matrix. Identity when absent.
    glm::vec3 row_u{1.0f, 0.0f, 0.0f}, row_v{0.0f, 1.0f, 0.0f};

    bool used() const { return image >= 0; }
};

// glTF 2.0 alphaMode: OPAQUE ignores alpha; MASK cuts where alpha < alphaCutoff; BLEND is
// rendered as stochastic transparency (a ray passes with probability 1 − alpha).
enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// glTF 2.0 metallic-roughness surface that may also emit (DESIGN.md "Radiometric contract").
// Default-constructed it is the course's Lambertian reflector: the glTF importer sets the
// specification's defaults (metallic 1, specular 1) itself.
struct Material {
    std::string name;
    glm::vec3 albedo{1.0f};     // baseColorFactor.rgb (glTF default: white)
    glm::vec3 emission{0.0f};   // Le = emissiveFactor × KHR_materials_emissive_strength
    bool double_sided = false;  // emits (and is shaded) on both faces
    float metallic = 0.0f;      // metallicFactor, [0, 1]
    float roughness = 1.0f;     // roughnessFactor, [0, 1]; GGX α = roughness²
    float specular = 0.0f;      // KHR_materials_specular.specularFactor, [0, 1]; glTF default 1
    glm::vec3 specular_color{1.0f};  // KHR_materials_specular.specularColorFactor, ≥ 0
    // KHR_materials_ior: the dielectric's F0 = ((ior − 1)/(ior + 1))², 0.04 at the default 1.5;
    // ior is ≥ 1, or exactly 0, the extension's specular-glossiness mode (F = 1 everywhere).
    float ior = 1.5f;
    // KHR_materials_transmission.transmissionFactor, [0, 1]: the share of the dielectric that is
    // a rough dielectric BTDF (glass) instead of the diffuse base; 0 is opaque.
    float transmission = 0.0f;
    // KHR_materials_volume with thicknessFactor > 0: a transmissive surface bounds a volume
    // (refraction, attenuation inside); else it is thin-walled.
    bool volume = false;
    glm::vec3 attenuation_color{1.0f};  // attenuationColor, [0, 1]
    float attenuation_distance = std::numeric_limits<float>::infinity();  // > 0; ∞: no loss
    float alpha = 1.0f;  // baseColorFactor.a, [0, 1]
    AlphaMode alpha_mode = AlphaMode::Opaque;
    float alpha_cutoff = 0.5f;  // MASK only
    // Texture slots; each multiplies its factor (glTF 2.0 "Metallic-Roughness Material").
    TextureRef base_color_texture;          // sRGB; RGB × albedo, A × alpha
    TextureRef metallic_roughness_texture;  // linear; B × metallic, G × roughness
    TextureRef normal_texture;              // linear; tangent-space normal, scaled in x and y
    float normal_scale = 1.0f;              // normalTexture.scale
    TextureRef emissive_texture;            // sRGB; RGB × emission
    TextureRef transmission_texture;        // linear; R × transmission

    // The surface needs the textured kernels (-D MCRT_TEXTURES): a texture, or alpha that a ray
    // query must test (MASK, BLEND).
    bool textured() const {
        return base_color_texture.used() || metallic_roughness_texture.used() ||
               normal_texture.used() || emissive_texture.used() || transmission_texture.used() ||
               alpha_mode != AlphaMode::Opaque;
    }

    // Exactly the Lambertian albedo/π: no metal, and no specular layer on the dielectric.
    bool lambertian() const { return metallic == 0.0f && specular == 0.0f && transmission == 0.0f; }
};

// KHR_materials_ior's dielectric F0 = ((ior − 1)/(ior + 1))², in double and rounded once: exactly
// 0.04f at the default ior 1.5, 1 at ior 0 (the extension's specular-glossiness mode).
inline float dielectric_f0(float ior) {
    const double r = (double(ior) - 1.0) / (double(ior) + 1.0);
    return float(r * r);
}

// Beer–Lambert attenuation per unit length in bits, −log2(attenuationColor)/attenuationDistance
// per channel (transmittance 2^(−a·t), kernels/materials/dielectric.cl): 0 for an infinite distance
// or a white colour; a black channel's is large but finite (1e30), so that a·0 stays 0.
inline glm::dvec3 volume_attenuation(const Material& m) {
    glm::dvec3 a(0.0);
    if (!std::isfinite(m.attenuation_distance)) return a;
    for (int c = 0; c < 3; ++c) {
        const double color = m.attenuation_color[c];
        a[c] =
            color > 0.0 ? std::min(-std::log2(color) / double(m.attenuation_distance), 1e30) : 1e30;
    }
    return a;
}

// `--materials lambert`: every surface the course's Lambertian reflector of its baseColor.
void make_lambertian(std::vector<Material>& materials);

// Perspective camera; looks down its local −Z with +Y up, as glTF.
struct Camera {
    std::string name;
    glm::mat4 camera_to_world{1.0f};  // rigid part only: columns are right, up, back, eye
    float yfov = 0.785398f;           // vertical field of view, radians
    int gltf_index = -1;              // its glTF `cameras` index; -1 for one made by mcrt
};

// A triangle soup in world space. Triangle t has vertices positions[3t .. 3t+2],
// counter-clockwise seen from its front face, and material materials[triangle_material[t]].
// A scene with a textured material (Material::textured) also has the corners' attributes that
// textures read, parallel to positions; an untextured scene leaves them empty.
struct Scene {
    std::string path;
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> triangle_material;
    std::vector<Material> materials;
    std::vector<Camera> cameras;  // perspective camera nodes, in default-scene traversal order
    std::vector<std::string> gltf_camera_types;  // per glTF camera: "perspective", "orthographic"
    std::vector<TextureImage> images;            // those the materials' texture slots name
    std::vector<glm::vec4> texcoords;  // per corner: .xy TEXCOORD_0, .zw TEXCOORD_1 (0 absent)
    // Per corner, world space, for materials with a normal texture (zero for the others): the
    // unit vertex normal (the face's where the primitive has none) and the unit tangent with
    // its handedness in w (±1; bitangent = w · cross(normal, tangent)), MikkTSpace where the
    // primitive has no TANGENT.
    std::vector<glm::vec3> normals;
    std::vector<glm::vec4> tangents;
    // KHR_lights_punctual lights, one per node that holds one, in default-scene traversal order.
    std::vector<PunctualLight> punctual_lights;

    bool textured() const { return !texcoords.empty(); }

    size_t triangle_count() const { return triangle_material.size(); }
    glm::vec3 bounds_min() const;
    glm::vec3 bounds_max() const;
};

// An emissive triangle that can be sampled: non-zero Le and non-zero area.
struct EmissiveTriangle {
    uint32_t triangle;  // index into Scene
    float area;
    float power;  // luminance(Le) × area × π, ×2 when double-sided
};

// Emissive triangles of the scene; zero-area (degenerate) and zero-radiance ones are dropped.
std::vector<EmissiveTriangle> collect_emitters(const Scene& scene);

// Rec. 709 luminance of linear RGB.
inline float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// The bench camera of DESIGN.md: eye = c + diag·(0.35, 0.30, 0.55), looking at c, 45°.
Camera bench_camera(const Scene& scene);

}  // namespace mcrt
