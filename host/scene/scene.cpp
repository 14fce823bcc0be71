// Scene queries: bounds, the emissive triangles and the bench camera (DESIGN.md).
#include "scene/scene.h"

#include <cmath>
#include <glm/gtc/constants.hpp>
#include <limits>

namespace mcrt {

namespace {

bool is_finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

// An empty scene has the empty box at the origin, so that callers never see ±infinity.
glm::vec3 Scene::bounds_min() const {
    if (positions.empty()) return glm::vec3(0.0f);
    glm::vec3 lo = positions.front();
    for (const glm::vec3& p : positions) lo = glm::min(lo, p);
    return lo;
}

glm::vec3 Scene::bounds_max() const {
    if (positions.empty()) return glm::vec3(0.0f);
    glm::vec3 hi = positions.front();
    for (const glm::vec3& p : positions) hi = glm::max(hi, p);
    return hi;
}

void make_lambertian(std::vector<Material>& materials) {
    for (Material& m : materials) {
        m.metallic = 0.0f;
        m.specular = 0.0f;
    }
}

std::vector<EmissiveTriangle> collect_emitters(const Scene& scene) {
    std::vector<EmissiveTriangle> emitters;
    for (size_t t = 0; t < scene.triangle_count(); ++t) {
        const Material& material = scene.materials[scene.triangle_material[t]];
        const float Le_luminance = luminance(material.emission);
        if (!(Le_luminance > 0.0f) || !std::isfinite(Le_luminance)) continue;

        // Area in double precision: the cross product of long thin triangles cancels badly.
        const glm::dvec3 p0 = scene.positions[3 * t];
        const glm::dvec3 p1 = scene.positions[3 * t + 1];
        const glm::dvec3 p2 = scene.positions[3 * t + 2];
        const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
        if (!is_finite(n)) continue;
        const float area = static_cast<float>(0.5 * glm::length(n));
        // Degenerate: its normal (and 1/area, the area pdf) would not be representable.
        if (!(area > std::numeric_limits<float>::min()) || !std::isfinite(area)) continue;

        const float sides = material.double_sided ? 2.0f : 1.0f;
        const float power = Le_luminance * area * glm::pi<float>() * sides;
        emitters.push_back(EmissiveTriangle{static_cast<uint32_t>(t), area, power});
    }
    return emitters;
}

Camera bench_camera(const Scene& scene) {
    // Benchmark contract: c = (bmin + bmax)/2, diag = |bmax − bmin|.
    glm::dvec3 bmin = scene.bounds_min();
    glm::dvec3 bmax = scene.bounds_max();
    glm::dvec3 c = 0.5 * (bmin + bmax);
    double diag = glm::length(bmax - bmin);
    // Empty or point-like scene (or one the bounds cannot describe): a unit view of the origin
    // side of the box, so the camera is still a valid frame.
    if (!is_finite(c)) c = glm::dvec3(0.0);
    if (!(diag > 0.0) || !std::isfinite(diag)) diag = 1.0;

    const glm::dvec3 eye = c + diag * glm::dvec3(0.35, 0.30, 0.55);
    const glm::dvec3 forward = glm::normalize(c - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
    const glm::dvec3 up = glm::cross(right, forward);

    Camera camera;
    camera.name = "bench";
    camera.camera_to_world = glm::mat4(glm::dmat4(glm::dvec4(right, 0.0), glm::dvec4(up, 0.0),
                                                  glm::dvec4(-forward, 0.0), glm::dvec4(eye, 1.0)));
    camera.yfov = glm::radians(45.0f);
    return camera;
}

}  // namespace mcrt
