// The rays of DESIGN.md's benchmark contract, generated on the host before any timing.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scene/scene.h"
#include "shared_types.h"

namespace mcrt {

// Rays as trace.cl reads them: origins[k].xyz with t_max in .w, directions[k].xyz.
struct RayBatch {
    std::vector<gpu::float4> origins, directions;
    size_t size() const { return origins.size(); }
};

// The frame of the contract: bmin, bmax over all vertices, c their midpoint, diag |bmax − bmin|.
struct BenchFrame {
    glm::vec3 bmin{0.0f}, bmax{0.0f}, c{0.0f};
    float diag = 1.0f;
};
BenchFrame bench_frame(const Scene& scene);

// A primary hit as both tracers must agree on: the point and the geometric normal of the hit
// triangle turned to face the incoming ray.
struct SurfacePoint {
    glm::vec3 p, n;
};

// Surface points of the primary rays that hit, in ray order, from trace_closest's output
// (t, b1, b2, the scene's triangle index as uint bits; NO_HIT on a miss) and the scene's
// positions (three per triangle).
std::vector<SurfacePoint> surface_points(const RayBatch& primary,
                                         const std::vector<gpu::float4>& hits,
                                         const std::vector<glm::vec3>& positions);

// One closest-hit ray per pixel through its centre, row-major from the top-left pixel,
// t_max = FLT_MAX (finite: the kernels may be built with -cl-fast-relaxed-math).
RayBatch primary_rays(const gpu::CameraGpu& camera, int width, int height);

// One any-hit ray per surface point from p + 1e-4·diag·n to a uniform point of the square
// y = bmax.y + 0.1·diag, x ∈ c.x ± 0.1·diag, z ∈ c.z ± 0.1·diag; the direction is normalised and
// t_max is the distance to that point.
RayBatch shadow_rays(const BenchFrame& frame, const std::vector<SurfacePoint>& points,
                     uint64_t seed);

// Four any-hit rays per surface point, cosine-distributed about n, from the same origin as the
// shadow ray, t_max = 0.1·diag.
RayBatch ambient_rays(const BenchFrame& frame, const std::vector<SurfacePoint>& points,
                      uint64_t seed);

// Uniform float in [0, 1) as a pure function of (seed, stream, dimension): the rays do not
// depend on the order in which they are generated.
float bench_random(uint64_t seed, uint64_t stream, uint32_t dimension);

}  // namespace mcrt
