// Scene queries: bounds, the emissive triangles and the bench camera (DESIGN.md).
#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <limits>

#include "scene/texture_lookup.h"

namespace mcrt {

namespace {

bool is_finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// The texture coordinates of corner k of triangle t in the set `ref` reads.
glm::vec2 corner_uv(const Scene& scene, size_t t, int k, const TextureRef& ref) {
    const glm::vec4& uv = scene.texcoords[3 * t + size_t(k)];
    return ref.texcoord == 1 ? glm::vec2(uv.z, uv.w) : glm::vec2(uv.x, uv.y);
}

// Texels of `ref`'s image that triangle t covers (its transformed UV area × the image's size).
double covered_texels(const Scene& scene, size_t t, const TextureRef& ref) {
    if (!ref.used() || scene.texcoords.empty()) return 0.0;
    const TextureImage& image = scene.images[size_t(ref.image)];
    glm::dvec2 q[3];
    for (int k = 0; k < 3; ++k) {
        const glm::dvec2 st = corner_uv(scene, t, k, ref);
        q[k] = {glm::dot(glm::dvec3(ref.row_u), glm::dvec3(st, 1.0)),
                glm::dot(glm::dvec3(ref.row_v), glm::dvec3(st, 1.0))};
    }
    const glm::dvec2 a = q[1] - q[0], b = q[2] - q[0];
    return 0.5 * std::abs(a.x * b.y - a.y * b.x) * double(image.width) * double(image.height);
}

// The mean over triangle t of what its emission is multiplied by where textures vary it (the
// emissive texture's luminance-weighted colour, alpha's cut or cover), by the midpoint rule on
// m² equal sub-triangles, m chosen so that each covered texel gets about four points: the
// emitted power that light selection follows (DESIGN.md "Radiometric contract").
double textured_emission_mean(const Scene& scene, size_t t, const Material& m) {
    if (scene.texcoords.empty()) return 1.0;
    const double texels = std::max(
        covered_texels(scene, t, m.emissive_texture),
        m.alpha_mode == AlphaMode::Opaque ? 0.0 : covered_texels(scene, t, m.base_color_texture));
    const int n = int(std::ceil(std::sqrt(std::clamp(4.0 * texels, 1.0, 65536.0))));
    const glm::vec3 Le = m.emission;
    const double Le_luminance = luminance(Le);
    double sum = 0.0;
    auto point = [&](double b1, double b2) {
        const double b0 = 1.0 - b1 - b2;
        const glm::vec4 uv = float(b0) * scene.texcoords[3 * t] +
                             float(b1) * scene.texcoords[3 * t + 1] +
                             float(b2) * scene.texcoords[3 * t + 2];
        auto set = [&](const TextureRef& ref) {
            return ref.texcoord == 1 ? glm::vec2(uv.z, uv.w) : glm::vec2(uv.x, uv.y);
        };
        glm::vec3 e = Le;
        if (m.emissive_texture.used()) {
            e *= glm::vec3(texture_lookup(scene.images[size_t(m.emissive_texture.image)],
                                          m.emissive_texture, set(m.emissive_texture)));
        }
        double cover = 1.0;
        if (m.alpha_mode != AlphaMode::Opaque) {
            float a = m.alpha;
            if (m.base_color_texture.used()) {
                a *= texture_lookup(scene.images[size_t(m.base_color_texture.image)],
                                    m.base_color_texture, set(m.base_color_texture))
                         .w;
            }
            cover = m.alpha_mode == AlphaMode::Mask ? (a >= m.alpha_cutoff ? 1.0 : 0.0) : a;
        }
        sum += luminance(e) * cover;
    };
    for (int i = 0; i < n; ++i) {
        for (int j = 0; i + j < n; ++j) {
            point((i + 1.0 / 3.0) / n, (j + 1.0 / 3.0) / n);
            if (i + j < n - 1) point((i + 2.0 / 3.0) / n, (j + 2.0 / 3.0) / n);
        }
    }
    return sum / (double(n) * n) / Le_luminance;
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
        m.transmission = 0.0f;
        m.transmission_texture = TextureRef{};  // nothing left for it to scale
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
        float power = Le_luminance * area * glm::pi<float>() * sides;
        if (material.emissive_texture.used() || material.alpha_mode != AlphaMode::Opaque) {
            // A textured emitter whose texels are all black (or cut away) here is no light.
            const double mean = textured_emission_mean(scene, t, material);
            if (!(mean > 0.0)) continue;
            power = float(double(power) * mean);
        }
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
