// Scenes with exact images, for the estimator tests: a polygon light over a diffuse plane
// (Lambert's formula) and their camera.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/gpu_scene.h"
#include "scene_builders.h"

namespace mcrt::test {

// The mean over each pixel's jittered footprint (box filter) of value(eye, d) for the rays
// eye + t·d through the pixel: a q×q midpoint rule over the jitter square, 3 doubles per pixel.
template <typename F>
std::vector<double> exact_pixel_image(const Camera& camera, int w, int h, int q, F value) {
    gpu::CameraGpu cam = make_gpu_camera(camera, w, h);
    glm::dvec3 eye(cam.eye.x, cam.eye.y, cam.eye.z),
        fwd(cam.forward.x, cam.forward.y, cam.forward.z),
        right(cam.right.x, cam.right.y, cam.right.z), up(cam.up.x, cam.up.y, cam.up.z);
    std::vector<double> img(3 * size_t(w) * h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            for (int b = 0; b < q; ++b)
                for (int a = 0; a < q; ++a) {
                    double x = 2.0 * (i + (a + 0.5) / q) / w - 1.0;
                    double y = 1.0 - 2.0 * (j + (b + 0.5) / q) / h;
                    glm::dvec3 v = value(eye, fwd + x * right + y * up);
                    for (int c = 0; c < 3; ++c) img[3 * (size_t(j) * w + i) + c] += v[c] / (q * q);
                }
    return img;
}

// As exact_pixel_image with q = 8, for value(p) at the point p where the ray meets y = 0.
template <typename F>
std::vector<double> exact_plane_image(const Camera& camera, int w, int h, F value) {
    return exact_pixel_image(camera, w, h, 8, [&](glm::dvec3 eye, glm::dvec3 d) {
        return value(eye + (-eye.y / d.y) * d);
    });
}

// The mean of an image of 3 doubles per pixel.
inline glm::dvec3 image_mean(const std::vector<double>& img) {
    glm::dvec3 m(0.0);
    size_t n = img.size() / 3;
    for (size_t p = 0; p < n; ++p)
        for (int c = 0; c < 3; ++c) m[c] += img[3 * p + c] / double(n);
    return m;
}

// Camera at `eye` looking straight down −Y, image up = −Z.
inline Camera looking_down(glm::vec3 eye, float yfov) {
    Camera c;
    c.camera_to_world = glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0, 0, -1, 0),
                                  glm::vec4(0, 1, 0, 0), glm::vec4(eye, 1));
    c.yfov = yfov;
    return c;
}

// Irradiance at x (normal n) from a convex polygon of uniform radiance L wholly above x's
// horizon: E = L/2 · |Σ Θ_i (Γ_i · n)| (Lambert 1760; Arvo 1995, "Applications of Irradiance
// Tensors", eq. 1), Θ_i the angle the edge subtends, Γ_i the unit normal of its plane through x.
inline double lambert_irradiance(const std::vector<glm::dvec3>& polygon, glm::dvec3 x, glm::dvec3 n,
                                 double L) {
    double sum = 0;
    for (size_t i = 0; i < polygon.size(); ++i) {
        glm::dvec3 a = glm::normalize(polygon[i] - x);
        glm::dvec3 b = glm::normalize(polygon[(i + 1) % polygon.size()] - x);
        double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        sum += theta * glm::dot(glm::normalize(glm::cross(a, b)), n);
    }
    return 0.5 * L * std::abs(sum);
}

struct PolygonLight {
    std::vector<glm::dvec3> polygon;
    glm::dvec3 Le;
};

// The plane y = 0 (albedo `albedo`) lit by `lights` (facing down), seen from above.
struct PlaneScene {
    Scene scene;
    Camera camera = looking_down(glm::vec3(0, 3, 0), glm::radians(40.0f));
    glm::dvec3 albedo{0.6, 0.5, 0.4};
    std::vector<PolygonLight> lights;

    PlaneScene() {
        uint32_t floor = add_material(scene, albedo);
        add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
        // A quad light (two triangles) and a small, brighter triangle light, both outside the
        // camera's view and both facing −Y.
        add_light({{0.8, 1, -0.25}, {1.3, 1, -0.25}, {1.3, 1, 0.25}, {0.8, 1, 0.25}}, {5, 4, 3});
        add_light({{-1.4, 0.7, 0.2}, {-1.0, 0.7, 0.2}, {-1.2, 0.75, 0.5}}, {40, 30, 60});
    }

    void add_light(std::vector<glm::dvec3> polygon, glm::dvec3 Le) {
        uint32_t m = add_material(scene, glm::vec3(0.0f), glm::vec3(Le));
        if (polygon.size() == 4)
            add_quad(scene, polygon[0], polygon[1], polygon[2], polygon[3], m);
        else
            add_triangle(scene, polygon[0], polygon[1], polygon[2], m);
        lights.push_back({polygon, Le});
    }

    // Exact pixel values: albedo/π · E on the plane, averaged over each pixel's footprint.
    std::vector<double> exact_image(int w, int h) const {
        return exact_plane_image(camera, w, h, [&](glm::dvec3 p) {
            glm::dvec3 v(0.0);
            for (const PolygonLight& l : lights)
                v += albedo / M_PI * l.Le * lambert_irradiance(l.polygon, p, {0, 1, 0}, 1.0);
            return v;
        });
    }
};

// The closed furnace: a sphere emitting Le inward and reflecting albedo around the camera, so
// that every point sees Le in every direction (a path of N reflections sums Le albedo^k).
struct FurnaceScene {
    Scene scene;
    Camera camera = looking_down(glm::vec3(0.1f, 0.2f, 0.0f), glm::radians(90.0f));
    glm::vec3 Le, albedo;

    explicit FurnaceScene(glm::vec3 Le_ = glm::vec3(0.5f, 1.0f, 2.0f),
                          glm::vec3 albedo_ = glm::vec3(0.8f, 0.5f, 0.2f), int slices = 24,
                          int stacks = 12)
        : Le(Le_), albedo(albedo_) {
        uint32_t m = add_material(scene, albedo, Le);
        add_sphere(scene, glm::vec3(0.0f), 1.0f, slices, stacks, m, /*inward=*/true);
    }
};

}  // namespace mcrt::test
