// Device BVH traversal of the 4-wide tree (closest hit, any hit) against a brute-force reference
// in double precision on the same rays, a deep tree, and the watertightness of the ray–triangle
// test.
#include <catch2/catch.hpp>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>

#include "bvh/bvh.h"
#include "cl/cl_error.h"
#include "cl/program.h"
#include "device_support.h"
#include "scene_builders.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

struct RaySet {
    std::vector<gpu::float4> origins, directions;  // origins[k].w = t_max
};

struct Tracer {
    DeviceContext device = first_device();
    cl::Program program = cached_program(device, "trace.cl", "");

    template <typename T>
    cl::Buffer buffer(const std::vector<T>& v) {
        cl_int status;
        cl::Buffer b(device.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                     const_cast<T*>(v.data()), &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        return b;
    }

    template <typename Out>
    std::vector<Out> run(const char* entry, const Bvh& bvh, const RaySet& rays) {
        cl::Kernel k = make_kernel(program, entry);
        std::vector<Out> out(rays.origins.size());
        cl::Buffer nodes = buffer(bvh.nodes4),
                   packets = buffer(bvh.packets.empty() ? std::vector<gpu::TrianglePacket>(1)
                                                        : bvh.packets);
        cl::Buffer o = buffer(rays.origins), d = buffer(rays.directions), result = buffer(out);
        CL_CHECK(k.setArg(0, nodes));
        CL_CHECK(k.setArg(1, packets));
        CL_CHECK(k.setArg(2, o));
        CL_CHECK(k.setArg(3, d));
        CL_CHECK(k.setArg(4, cl_uint(out.size())));
        CL_CHECK(k.setArg(5, result));
        CL_CHECK(device.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(out.size())));
        CL_CHECK(device.queue.enqueueReadBuffer(result, CL_TRUE, 0, out.size() * sizeof(Out),
                                                out.data()));
        return out;
    }
};

uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// Möller–Trumbore in double precision: the reference distance, or +inf on a miss.
double reference_t(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& p0,
                   const glm::dvec3& p1, const glm::dvec3& p2) {
    glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
    double det = glm::dot(e1, pv);
    if (det == 0.0) return INFINITY;
    glm::dvec3 tv = o - p0;
    double u = glm::dot(tv, pv) / det;
    glm::dvec3 qv = glm::cross(tv, e1);
    double v = glm::dot(d, qv) / det;
    if (u < 0 || v < 0 || u + v > 1) return INFINITY;
    double t = glm::dot(e2, qv) / det;
    return t > 0 ? t : INFINITY;
}

// Closest reference hit over all triangles; *margin is how close the ray passes to an edge of
// the hit triangle (in barycentric units), so near-edge disagreements can be told apart.
double brute_force(const Scene& s, const glm::dvec3& o, const glm::dvec3& d, double t_max,
                   int* triangle) {
    double best = t_max;
    *triangle = -1;
    for (size_t t = 0; t < s.triangle_count(); ++t) {
        double th =
            reference_t(o, d, s.positions[3 * t], s.positions[3 * t + 1], s.positions[3 * t + 2]);
        if (th < best) best = th, *triangle = int(t);
    }
    return best;
}

RaySet random_rays(int n, uint32_t seed, float t_max) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    RaySet rays;
    for (int k = 0; k < n; ++k) {
        glm::vec3 o(u(rng) * 1.4f - 0.2f, u(rng) * 1.4f - 0.2f, u(rng) * 1.4f - 0.2f);
        glm::vec3 target(u(rng), u(rng), u(rng));
        glm::vec3 d = glm::normalize(target - o);
        rays.origins.push_back({o.x, o.y, o.z, t_max});
        rays.directions.push_back({d.x, d.y, d.z, 0.0f});
    }
    return rays;
}

}  // namespace

TEST_CASE("closest hit on the device agrees with brute force in double precision", "[traversal]") {
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.5f));
    add_random_triangles(scene, 3000, 0.1f, m, 7);
    add_random_triangles(scene, 50, 0.6f, m, 8);  // large ones overlap many leaves
    Bvh bvh = build_bvh(scene);
    RaySet rays = random_rays(4000, 11, FLT_MAX);
    Tracer tracer;
    auto hits = tracer.run<gpu::float4>("trace_closest", bvh, rays);

    int disagreements = 0, hits_found = 0;
    for (size_t k = 0; k < hits.size(); ++k) {
        glm::dvec3 o(rays.origins[k].x, rays.origins[k].y, rays.origins[k].z);
        glm::dvec3 d(rays.directions[k].x, rays.directions[k].y, rays.directions[k].z);
        int ref_triangle;
        double ref = brute_force(scene, o, d, INFINITY, &ref_triangle);
        uint32_t scene_triangle = bits(hits[k].w);
        bool device_hit = scene_triangle != 0xffffffffu;
        if (device_hit != (ref_triangle >= 0)) {
            ++disagreements;
            continue;
        }
        if (!device_hit) continue;
        ++hits_found;
        REQUIRE(scene_triangle < scene.triangle_count());
        CHECK(hits[k].x == Approx(ref).epsilon(1e-4));
        // Another triangle at the same distance (a tie) is as good an answer.
        if (int(scene_triangle) != ref_triangle) {
            double t_other = reference_t(o, d, scene.positions[3 * scene_triangle],
                                         scene.positions[3 * scene_triangle + 1],
                                         scene.positions[3 * scene_triangle + 2]);
            CHECK(t_other == Approx(ref).epsilon(1e-5));
        }
    }
    CHECK(hits_found > 1000);
    // Rays that graze an edge within float rounding may differ; random rays almost never do.
    CHECK(disagreements <= 2);
}

TEST_CASE("any hit on the device agrees with closest hit on segments", "[traversal]") {
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.5f));
    add_random_triangles(scene, 2000, 0.1f, m, 3);
    Bvh bvh = build_bvh(scene);
    RaySet rays = random_rays(4000, 5, 0.5f);
    Tracer tracer;
    auto closest = tracer.run<gpu::float4>("trace_closest", bvh, rays);
    auto occluded = tracer.run<cl_uint>("trace_any", bvh, rays);
    int blocked = 0;
    for (size_t k = 0; k < occluded.size(); ++k) {
        bool hit = bits(closest[k].w) != 0xffffffffu;
        CHECK(bool(occluded[k]) == hit);
        blocked += hit;
    }
    CHECK(blocked > 500);
    CHECK(blocked < 3500);
}

TEST_CASE("no ray escapes a closed mesh through its edges or vertices (watertight)",
          "[traversal]") {
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.5f));
    add_sphere(scene, glm::vec3(0.3f, -0.2f, 0.1f), 1.0f, 48, 24, m);
    Bvh bvh = build_bvh(scene);
    // Aim from inside exactly at every vertex and edge midpoint: the hardest rays.
    RaySet rays;
    glm::vec3 origins[] = {{0.3f, -0.2f, 0.1f}, {0.5f, 0.1f, -0.2f}, {0.0f, -0.6f, 0.4f}};
    for (const glm::vec3& o : origins)
        for (size_t t = 0; t < scene.triangle_count(); ++t)
            for (int e = 0; e < 3; ++e) {
                glm::vec3 a = scene.positions[3 * t + e], b = scene.positions[3 * t + (e + 1) % 3];
                for (glm::vec3 target : {a, 0.5f * (a + b)}) {
                    glm::vec3 d = target - o;  // unnormalised on purpose
                    rays.origins.push_back({o.x, o.y, o.z, FLT_MAX});
                    rays.directions.push_back({d.x, d.y, d.z, 0.0f});
                }
            }
    Tracer tracer;
    auto hits = tracer.run<gpu::float4>("trace_closest", bvh, rays);
    size_t misses = 0;
    for (const gpu::float4& h : hits) misses += bits(h.w) == 0xffffffffu;
    INFO(rays.origins.size() << " rays");
    CHECK(misses == 0);
}

TEST_CASE("ties at shared edges and vertices go to the smallest scene index, whatever the tree",
          "[traversal]") {
    // Rays aimed from inside a sphere at its vertices and edge midpoints hit two or more
    // triangles at the same t. Trees of other shapes order the leaves differently; the hit must
    // not follow that order, so that any tree (another leaf size, a tree per device) renders
    // the same image.
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.5f));
    add_sphere(scene, glm::vec3(0.3f, -0.2f, 0.1f), 1.0f, 24, 12, m);
    RaySet rays;
    const glm::vec3 o(0.35f, -0.1f, 0.05f);
    for (size_t t = 0; t < scene.triangle_count(); ++t)
        for (int e = 0; e < 3; ++e) {
            glm::vec3 a = scene.positions[3 * t + e], b = scene.positions[3 * t + (e + 1) % 3];
            for (glm::vec3 target : {a, 0.5f * (a + b)}) {
                glm::vec3 d = target - o;
                rays.origins.push_back({o.x, o.y, o.z, FLT_MAX});
                rays.directions.push_back({d.x, d.y, d.z, 0.0f});
            }
        }
    Tracer tracer;
    BvhBuildOptions wide, narrow;
    narrow.max_leaf_size = 2;
    narrow.bins = 5;
    const Bvh a = build_bvh(scene, wide), b = build_bvh(scene, narrow);
    size_t reordered = 0;  // scene triangles whose leaf positions differ between the two trees
    for (size_t i = 0; i < a.triangles.size(); ++i)
        reordered += a.triangles[i].index != b.triangles[i].index;
    REQUIRE(reordered > scene.triangle_count() / 2);
    auto hits_a = tracer.run<gpu::float4>("trace_closest", a, rays);
    auto hits_b = tracer.run<gpu::float4>("trace_closest", b, rays);
    size_t differ = 0, ties = 0;
    for (size_t k = 0; k < hits_a.size(); ++k) {
        differ += std::memcmp(&hits_a[k], &hits_b[k], sizeof(gpu::float4)) != 0;
        // Whether the ray meets two or more triangles at its hit's t (the double reference
        // within rounding): the rays must exercise ties for the comparison to mean anything.
        glm::dvec3 od(o), d(rays.directions[k].x, rays.directions[k].y, rays.directions[k].z);
        int at_t = 0;
        for (size_t t = 0; t < scene.triangle_count(); ++t) {
            double tt = reference_t(od, d, scene.positions[3 * t], scene.positions[3 * t + 1],
                                    scene.positions[3 * t + 2]);
            at_t += tt > 0.0 && std::abs(tt - double(hits_a[k].x)) <= 1e-5 * tt;
        }
        ties += at_t > 1;
    }
    INFO(rays.origins.size() << " rays, " << ties << " at shared edges or vertices");
    CHECK(ties > rays.origins.size() / 2);
    CHECK(differ == 0);
}

TEST_CASE("the device sees Bvh4Node with the host's size", "[traversal]") {
    DeviceContext device = first_device();
    const std::string source = kernel_source("shared_types.h") +
                               "kernel void bvh4_node_size(global uint* size) {\n"
                               "    size[0] = sizeof(Bvh4Node);\n"
                               "    size[1] = __alignof__(Bvh4Node);\n"
                               "}\n";
    cl::Program program = build_program(device.context, device.info.device, source, "");
    cl::Kernel k = make_kernel(program, "bvh4_node_size");
    cl_int status;
    cl::Buffer out(device.context, CL_MEM_WRITE_ONLY, 2 * sizeof(cl_uint), nullptr, &status);
    CL_CHECK_STATUS(status, "clCreateBuffer");
    CL_CHECK(k.setArg(0, out));
    CL_CHECK(device.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1)));
    cl_uint got[2] = {};
    CL_CHECK(device.queue.enqueueReadBuffer(out, CL_TRUE, 0, sizeof got, got));
    CHECK(got[0] == sizeof(gpu::Bvh4Node));
    CHECK(got[1] == alignof(gpu::Bvh4Node));
}

TEST_CASE("a deep 4-wide tree is traversed exactly (the stack bound holds)", "[traversal]") {
    // Triangles scattered log-uniformly over 28 decades: SAH peels them off one scale at a time,
    // giving a tree far deeper than log4(N), and rays from the origin cross every scale.
    Scene scene;
    uint32_t m = add_material(scene, glm::vec3(0.5f));
    std::mt19937 rng(21);
    std::uniform_real_distribution<float> decade(-14.0f, 14.0f), u(0.0f, 1.0f);
    for (int t = 0; t < 4000; ++t) {
        float x = std::pow(10.0f, decade(rng)), y = x * u(rng), z = x * u(rng), e = 0.2f * x;
        add_triangle(scene, {x, y, z}, {x + e, y, z}, {x, y + e, z}, m);
    }
    Bvh bvh = build_bvh(scene);
    INFO("binary depth " << bvh.stats.depth << ", 4-wide depth " << bvh.stats.depth4);
    CHECK(bvh.stats.depth4 >= 30);
    // Rays from near the origin at each triangle's centroid: they must hit it or something nearer.
    RaySet rays;
    for (size_t t = 0; t < scene.triangle_count(); ++t) {
        glm::vec3 c =
            (scene.positions[3 * t] + scene.positions[3 * t + 1] + scene.positions[3 * t + 2]) /
            3.0f;
        glm::vec3 o(-1e-20f, -2e-20f, -3e-20f), d = c - o;
        rays.origins.push_back({o.x, o.y, o.z, FLT_MAX});
        rays.directions.push_back({d.x, d.y, d.z, 0.0f});
    }
    Tracer tracer;
    auto hits = tracer.run<gpu::float4>("trace_closest", bvh, rays);
    auto occluded = tracer.run<cl_uint>("trace_any", bvh, rays);
    size_t misses = 0, beyond = 0, not_occluded = 0;
    for (size_t k = 0; k < hits.size(); ++k) {
        not_occluded += occluded[k] == 0u;
        if (bits(hits[k].w) == 0xffffffffu) {
            ++misses;
            continue;
        }
        beyond += hits[k].x > 1.0f + 1e-5f;  // the centroid is at t = 1
    }
    CHECK(misses == 0);
    CHECK(beyond == 0);
    CHECK(not_occluded == 0);
}

TEST_CASE("an empty scene is traversed without hits", "[traversal]") {
    Scene scene;
    Bvh bvh = build_bvh(scene);
    RaySet rays = random_rays(64, 1, FLT_MAX);
    Tracer tracer;
    auto hits = tracer.run<gpu::float4>("trace_closest", bvh, rays);
    for (const gpu::float4& h : hits) CHECK(bits(h.w) == 0xffffffffu);
    auto occluded = tracer.run<cl_uint>("trace_any", bvh, rays);
    for (cl_uint o : occluded) CHECK(o == 0u);
}
