#include "bench/bench_rays.h"

#include <cfloat>
#include <cmath>
#include <cstring>

namespace mcrt {
namespace {

gpu::float4 to_float4(const glm::vec3& v, float w) { return {v.x, v.y, v.z, w}; }
glm::vec3 to_vec3(const gpu::float4& v) { return {v.x, v.y, v.z}; }

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a well-mixed hash of a 64-bit counter.
uint64_t splitmix64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

// Orthonormal basis around a unit vector without branches on its sign's magnitude (Duff et al.
// 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1)).
void orthonormal_basis(const glm::vec3& n, glm::vec3* t, glm::vec3* b) {
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float bb = n.x * n.y * a;
    *t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    *b = glm::vec3(bb, sign + n.y * n.y * a, -n.y);
}

// Where shadow and ambient rays start: off the surface along the normal facing the ray.
glm::vec3 offset_origin(const BenchFrame& frame, const SurfacePoint& s) {
    return s.p + (1e-4f * frame.diag) * s.n;
}

}  // namespace

float bench_random(uint64_t seed, uint64_t stream, uint32_t dimension) {
    uint64_t h = splitmix64(splitmix64(seed ^ splitmix64(stream)) + dimension);
    return float(h >> 40) * (1.0f / 16777216.0f);  // 24 bits: exactly representable, < 1
}

BenchFrame bench_frame(const Scene& scene) {
    BenchFrame f;
    if (scene.positions.empty()) return f;
    f.bmin = scene.bounds_min();
    f.bmax = scene.bounds_max();
    f.c = 0.5f * (f.bmin + f.bmax);
    f.diag = glm::length(f.bmax - f.bmin);
    if (!(f.diag > 0.0f) || !std::isfinite(f.diag)) f.diag = 1.0f;
    return f;
}

RayBatch primary_rays(const gpu::CameraGpu& camera, int width, int height) {
    // DESIGN.md "Camera contract": film point ((2(i+0.5)/W − 1), (1 − 2(j+0.5)/H)).
    RayBatch rays;
    size_t n = size_t(width) * size_t(height);
    rays.origins.resize(n);
    rays.directions.resize(n);
    glm::vec3 eye = to_vec3(camera.eye), right = to_vec3(camera.right), up = to_vec3(camera.up),
              forward = to_vec3(camera.forward);
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            float x = 2.0f * (float(i) + 0.5f) / float(width) - 1.0f;
            float y = 1.0f - 2.0f * (float(j) + 0.5f) / float(height);
            glm::vec3 d = glm::normalize(forward + x * right + y * up);
            size_t k = size_t(j) * size_t(width) + size_t(i);
            rays.origins[k] = to_float4(eye, FLT_MAX);
            rays.directions[k] = to_float4(d, 0.0f);
        }
    return rays;
}

std::vector<SurfacePoint> surface_points(const RayBatch& primary,
                                         const std::vector<gpu::float4>& hits,
                                         const std::vector<glm::vec3>& positions) {
    std::vector<SurfacePoint> points;
    for (size_t k = 0; k < hits.size(); ++k) {
        const uint32_t triangle = gpu::as_uint(hits[k].w);
        if (triangle == MCRT_NO_HIT || 3 * size_t(triangle) + 2 >= positions.size()) continue;
        const glm::vec3* p = &positions[3 * size_t(triangle)];
        glm::vec3 o = to_vec3(primary.origins[k]), d = to_vec3(primary.directions[k]);
        glm::vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
        float len = glm::length(n);
        n = len > 0.0f ? n / len : -d;
        if (glm::dot(n, d) > 0.0f) n = -n;  // the geometric normal facing the ray
        points.push_back({o + hits[k].x * d, n});
    }
    return points;
}

RayBatch shadow_rays(const BenchFrame& frame, const std::vector<SurfacePoint>& points,
                     uint64_t seed) {
    RayBatch rays;
    rays.origins.resize(points.size());
    rays.directions.resize(points.size());
    float half = 0.1f * frame.diag;
    float y = frame.bmax.y + 0.1f * frame.diag;
    for (size_t k = 0; k < points.size(); ++k) {
        glm::vec3 o = offset_origin(frame, points[k]);
        glm::vec3 target(frame.c.x + half * (2.0f * bench_random(seed, k, 0) - 1.0f), y,
                         frame.c.z + half * (2.0f * bench_random(seed, k, 1) - 1.0f));
        glm::vec3 to = target - o;
        float distance = glm::length(to);
        glm::vec3 d = distance > 0.0f ? to / distance : glm::vec3(0.0f, 1.0f, 0.0f);
        rays.origins[k] = to_float4(o, distance);
        rays.directions[k] = to_float4(d, 0.0f);
    }
    return rays;
}

RayBatch ambient_rays(const BenchFrame& frame, const std::vector<SurfacePoint>& points,
                      uint64_t seed) {
    constexpr int kPerPoint = 4;
    RayBatch rays;
    rays.origins.resize(points.size() * kPerPoint);
    rays.directions.resize(points.size() * kPerPoint);
    float t_max = 0.1f * frame.diag;
    for (size_t k = 0; k < points.size(); ++k) {
        glm::vec3 o = offset_origin(frame, points[k]);
        glm::vec3 t, b;
        orthonormal_basis(points[k].n, &t, &b);
        for (int s = 0; s < kPerPoint; ++s) {
            // Malley's method: a uniform disk point lifted to the hemisphere has density
            // cosθ/π (PBRT 3rd ed. 13.6.3).
            size_t index = k * kPerPoint + size_t(s);
            float u1 = bench_random(seed, index, 0), u2 = bench_random(seed, index, 1);
            float r = std::sqrt(u1), phi = 6.28318530718f * u2;
            float x = r * std::cos(phi), y = r * std::sin(phi);
            float z = std::sqrt(std::max(0.0f, 1.0f - u1));
            glm::vec3 d = glm::normalize(x * t + y * b + z * points[k].n);
            rays.origins[index] = to_float4(o, t_max);
            rays.directions[index] = to_float4(d, 0.0f);
        }
    }
    return rays;
}

}  // namespace mcrt
