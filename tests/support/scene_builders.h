// Small scenes built in code for the kernel and estimator tests.
#pragma once

#include <cmath>
#include <random>

#include "scene/scene.h"

namespace mcrt::test {

inline uint32_t add_material(Scene& s, glm::vec3 albedo, glm::vec3 Le = glm::vec3(0.0f),
                             bool double_sided = false) {
    Material m;
    m.albedo = albedo;
    m.emission = Le;
    m.double_sided = double_sided;
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

inline void add_triangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material) {
    s.positions.insert(s.positions.end(), {a, b, c});
    s.triangle_material.push_back(material);
}

// Quad a, b, c, d (counter-clockwise seen from the front) as two triangles.
inline void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d,
                     uint32_t material) {
    add_triangle(s, a, b, c, material);
    add_triangle(s, a, c, d, material);
}

// Closed latitude–longitude sphere, facing outward (or inward): every ray from inside hits it.
inline void add_sphere(Scene& s, glm::vec3 centre, float radius, int slices, int stacks,
                       uint32_t material, bool inward = false) {
    auto vertex = [&](int i, int j) {
        // Poles are one shared point each (sin π is not exactly 0 in float).
        if (j == 0 || j == stacks) return centre + glm::vec3(0.0f, j == 0 ? radius : -radius, 0.0f);
        float phi = 2.0f * float(M_PI) * float(i % slices) / float(slices);
        float theta = float(M_PI) * float(j) / float(stacks);
        return centre + radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                           std::sin(theta) * std::sin(phi));
    };
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            glm::vec3 a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1),
                      d = vertex(i, j + 1);
            // Pole rows have one triangle per slice; inward reverses the winding.
            if (j > 0) add_triangle(s, a, inward ? c : b, inward ? b : c, material);
            if (j < stacks - 1) add_triangle(s, a, inward ? d : c, inward ? c : d, material);
        }
}

// A 6 × 6 floor of `albedo` at y = 0, to be seen from above; with hidden_light, an emitter
// under it facing down, which puts an area light beside the sky or the map in the light choice
// without lighting the floor.
inline Scene floor_scene(glm::dvec3 albedo, bool hidden_light) {
    Scene scene;
    uint32_t floor = add_material(scene, glm::vec3(albedo));
    add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
    if (hidden_light) {
        uint32_t light = add_material(scene, glm::vec3(0.0f), glm::vec3(10.0f));
        add_quad(scene, {-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}, light);
    }
    return scene;
}

// n random triangles with vertices in [0, 1]³ and edges up to `size` long.
inline void add_random_triangles(Scene& s, int n, float size, uint32_t material, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < n; ++k) {
        glm::vec3 a(u(rng), u(rng), u(rng));
        glm::vec3 b = a + size * (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f);
        glm::vec3 c = a + size * (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f);
        add_triangle(s, a, b, c, material);
    }
}

}  // namespace mcrt::test
