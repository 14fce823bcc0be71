// The minimal scene model: triangles, materials, camera — nothing else (DESIGN.md "Data flow").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mcrt {

// glTF 2.0 metallic-roughness surface that may also emit (DESIGN.md "Radiometric contract").
// Default-constructed it is the course's Lambertian reflector: the glTF importer sets the
// specification's defaults (metallic 1, specular 1) itself.
struct Material {
    std::string name;
    glm::vec3 albedo{1.0f};    // baseColorFactor.rgb (glTF default: white)
    glm::vec3 emission{0.0f};  // Le = emissiveFactor × KHR_materials_emissive_strength
    bool double_sided = false; // emits (and is shaded) on both faces
    float metallic = 0.0f;     // metallicFactor, [0, 1]
    float roughness = 1.0f;    // roughnessFactor, [0, 1]; GGX α = roughness²
    float specular = 0.0f;     // KHR_materials_specular.specularFactor, [0, 1]; glTF default 1
    glm::vec3 specular_color{1.0f};  // KHR_materials_specular.specularColorFactor, ≥ 0

    // Exactly the Lambertian albedo/π: no metal, and no specular layer on the dielectric.
    bool lambertian() const { return metallic == 0.0f && specular == 0.0f; }
};

// `--materials lambert`: every surface the course's Lambertian reflector of its baseColor.
void make_lambertian(std::vector<Material>& materials);

// Perspective camera; looks down its local −Z with +Y up, as glTF.
struct Camera {
    std::string name;
    glm::mat4 camera_to_world{1.0f};  // rigid part only: columns are right, up, back, eye
    float yfov = 0.785398f;           // vertical field of view, radians
};

// A triangle soup in world space. Triangle t has vertices positions[3t .. 3t+2],
// counter-clockwise seen from its front face, and material materials[triangle_material[t]].
struct Scene {
    std::string path;
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> triangle_material;
    std::vector<Material> materials;
    std::vector<Camera> cameras;  // in default-scene traversal order

    size_t triangle_count() const { return triangle_material.size(); }
    glm::vec3 bounds_min() const;
    glm::vec3 bounds_max() const;
};

// An emissive triangle that can be sampled: non-zero Le and non-zero area.
struct EmissiveTriangle {
    uint32_t triangle;  // index into Scene
    float area;
    float power;        // luminance(Le) × area × π, ×2 when double-sided
};

// Emissive triangles of the scene; zero-area (degenerate) and zero-radiance ones are dropped.
std::vector<EmissiveTriangle> collect_emitters(const Scene& scene);

// Rec. 709 luminance of linear RGB.
inline float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// The bench camera of DESIGN.md: eye = c + diag·(0.35, 0.30, 0.55), looking at c, 45°.
Camera bench_camera(const Scene& scene);

}  // namespace mcrt
