#include "bench/bench.h"

#include <CL/opencl.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>

#include "bench/bench_rays.h"
#include "bench/embree_tracer.h"
#include "bvh/bvh.h"
#include "cl/cl_error.h"
#include "cl/device.h"
#include "cl/device_select.h"
#include "cl/program.h"
#include "common/error.h"
#include "render/gpu_scene.h"
#include "render/memory_estimate.h"
#include "render/plan.h"
#include "scene/gltf_import.h"

namespace mcrt {
namespace {

// Fixed seeds: the same scene and resolution always give the same rays.
constexpr uint64_t kShadowSeed = 0x5348414430ull;   // "SHAD0"
constexpr uint64_t kAmbientSeed = 0x414d424930ull;  // "AMBI0"

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// What one tracer reported on one ray kind.
struct Timing {
    size_t hits = 0;
    double seconds_median = 0;
    double mrays_per_s(size_t count) const {
        return seconds_median > 0 ? double(count) / seconds_median * 1e-6 : 0.0;
    }
};

// mcrt's BVH on one OpenCL device, tracing with kernels/traversal/trace.cl.
class DeviceTracer {
  public:
    DeviceTracer(const DeviceInfo& info, const Bvh& bvh) : device_(info) {
        program_ = cached_program(device_, "trace.cl", "");
        nodes_ = upload(bvh.nodes4.data(), bvh.nodes4.size() * sizeof(gpu::Bvh4Node), "BVH nodes");
        std::vector<gpu::TrianglePacket> one(1);
        const auto& packets = bvh.packets.empty() ? one : bvh.packets;
        packets_ = upload(packets.data(), packets.size() * sizeof(gpu::TrianglePacket),
                          "triangle packets");
    }

    const DeviceInfo& info() const { return device_.info; }

    // A reference tracer run after each launch, timed on the wall clock: alternating the two
    // gives both the same share of a machine that other work loads unevenly.
    struct Reference {
        std::function<void()> trace;  // empty: no reference
        double seconds_median = 0;
    };

    // Closest hits (trace_closest's float4 per ray), timed: one warm-up launch, then the
    // median kernel time of `repeats` launches from profiling events.
    Timing closest(const RayBatch& rays, int repeats, std::vector<gpu::float4>* hits,
                   Reference* reference) {
        hits->assign(rays.size(), gpu::float4{0, 0, 0, 0});
        Timing timing =
            run("trace_closest", rays, repeats, hits->data(), sizeof(gpu::float4), reference);
        for (const gpu::float4& h : *hits) timing.hits += gpu::as_uint(h.w) != MCRT_NO_HIT;
        return timing;
    }

    // Occlusion (trace_any's uint per ray), timed as closest().
    Timing any(const RayBatch& rays, int repeats, std::vector<uint32_t>* occluded,
               Reference* reference) {
        occluded->assign(rays.size(), 0u);
        Timing timing =
            run("trace_any", rays, repeats, occluded->data(), sizeof(uint32_t), reference);
        for (uint32_t o : *occluded) timing.hits += o != 0;
        return timing;
    }

  private:
    cl::Buffer upload(const void* data, size_t bytes, const char* what) {
        bytes = std::max<size_t>(bytes, 16);
        if (bytes > device_.info.max_allocation)
            throw RuntimeError(std::string("bench: ") + what + " need " + std::to_string(bytes) +
                               " bytes, more than the device " + device_.info.name + " allocates");
        cl_int status;
        cl::Buffer b(device_.context, CL_MEM_READ_ONLY | (data ? CL_MEM_COPY_HOST_PTR : 0), bytes,
                     const_cast<void*>(data), &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        return b;
    }

    Timing run(const char* entry, const RayBatch& rays, int repeats, void* out, size_t out_size,
               Reference* reference) {
        Timing timing;
        size_t n = rays.size();
        if (n == 0) return timing;
        cl::Buffer origins = upload(rays.origins.data(), n * sizeof(gpu::float4), "ray origins");
        cl::Buffer directions =
            upload(rays.directions.data(), n * sizeof(gpu::float4), "ray directions");
        cl_int status;
        if (n * out_size > device_.info.max_allocation)
            throw RuntimeError("bench: too many rays for one buffer on " + device_.info.name);
        cl::Buffer result(device_.context, CL_MEM_WRITE_ONLY, n * out_size, nullptr, &status);
        CL_CHECK_STATUS(status, "clCreateBuffer");
        cl::Kernel kernel = make_kernel(program_, entry);
        CL_CHECK(kernel.setArg(0, nodes_));
        CL_CHECK(kernel.setArg(1, packets_));
        CL_CHECK(kernel.setArg(2, origins));
        CL_CHECK(kernel.setArg(3, directions));
        CL_CHECK(kernel.setArg(4, cl_uint(n)));
        CL_CHECK(kernel.setArg(5, result));
        std::vector<double> seconds, reference_seconds;
        for (int r = 0; r <= repeats; ++r) {  // launch 0 is the warm-up
            cl::Event done;
            CL_CHECK(device_.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(n),
                                                        cl::NullRange, nullptr, &done));
            CL_CHECK(done.wait());
            cl_ulong start = 0, end = 0;
            CL_CHECK(done.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
            CL_CHECK(done.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
            if (r > 0) seconds.push_back(double(end - start) * 1e-9);
            if (reference && reference->trace) {
                auto begin = std::chrono::steady_clock::now();
                reference->trace();
                auto finish = std::chrono::steady_clock::now();
                if (r > 0)
                    reference_seconds.push_back(
                        std::chrono::duration<double>(finish - begin).count());
            }
        }
        if (reference) reference->seconds_median = median(reference_seconds);
        CL_CHECK(device_.queue.enqueueReadBuffer(result, CL_TRUE, 0, n * out_size, out));
        timing.seconds_median = median(seconds);
        return timing;
    }

    DeviceContext device_;
    cl::Program program_;
    cl::Buffer nodes_, packets_;
};

// One row of the report.
struct KindResult {
    std::string kind;
    size_t count = 0;
    Timing mcrt;
    bool has_embree = false;
    Timing embree;
    size_t hit_mismatches = 0;       // rays where the tracers disagree on hit / miss
    size_t triangle_mismatches = 0;  // primary rays both hit, on different triangles
    // ... of them with hit distances further apart than rounding explains: one tracer missed a
    // nearer hit. The others are ties (coplanar or edge-sharing triangles at the same distance),
    // which the two break in their own orders.
    size_t triangle_mismatches_apart = 0;
};

// Hit distances of two tracers on the same ray count as one (a tie) within this relative
// difference: Embree's and mcrt's triangle tests round differently, by a few ulps.
constexpr float kTieRelative = 1e-5f;

}  // namespace

int run_bench(const BenchOptions& o, const std::function<void(const std::string&)>& warn) {
    DeviceInfo device = select_device(o.device, warn);

    check_host_memory("a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " bench",
                      bench_host_bytes(o.width, o.height));
    // One launch holds every ray (32 bytes) and its hit (16 bytes) on the device.
    const DeviceInfo& chosen = device;
    const uint64_t rays = uint64_t(o.width) * uint64_t(o.height);
    if (rays * 32 > chosen.max_allocation || rays * 48 > chosen.global_memory)
        throw RuntimeError("a " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                           " bench needs " + std::to_string(rays * 48 >> 20) + " MiB on device " +
                           std::to_string(o.device) + " (largest buffer " +
                           std::to_string(chosen.max_allocation >> 20) + " MiB, memory " +
                           std::to_string(chosen.global_memory >> 20) + " MiB)");

    Scene scene = load_gltf(o.scene, warn);
    if (scene.triangle_count() == 0) warn(o.scene + ": the scene has no triangles");
    Camera camera = choose_camera(scene, CameraChoice{-1, o.camera});
    BenchFrame frame = bench_frame(scene);

    Bvh bvh = build_bvh(scene, o.bvh);
    double bytes_per_triangle =
        scene.triangle_count() ? double(bvh.stats.bytes) / double(scene.triangle_count()) : 0.0;
    DeviceTracer tracer(device, bvh);
#ifdef MCRT_HAVE_EMBREE
    EmbreeTracer embree(scene);
#endif

    auto wanted = [&](const char* kind) { return o.rays.empty() || o.rays == kind; };
    std::vector<KindResult> results;

    // Primary rays: always traced, since the shadow and ambient rays start at mcrt's hits.
    RayBatch primary = primary_rays(make_gpu_camera(camera, o.width, o.height), o.width, o.height);
    std::vector<gpu::float4> primary_hits;
    {
        KindResult r;
        r.kind = "primary";
        r.count = primary.size();
        DeviceTracer::Reference reference;
        std::vector<uint32_t> embree_triangle;
        std::vector<float> embree_t;
#ifdef MCRT_HAVE_EMBREE
        if (wanted("primary"))
            reference.trace = [&] { embree.closest(primary, &embree_triangle, &embree_t); };
#endif
        r.mcrt =
            tracer.closest(primary, wanted("primary") ? o.repeats : 0, &primary_hits, &reference);
#ifdef MCRT_HAVE_EMBREE
        if (wanted("primary")) {
            r.has_embree = true;
            r.embree.seconds_median = reference.seconds_median;
            for (size_t k = 0; k < primary.size(); ++k) {
                uint32_t triangle = gpu::as_uint(primary_hits[k].w);
                bool mcrt_hit = triangle != MCRT_NO_HIT,
                     embree_hit = embree_triangle[k] != MCRT_NO_HIT;
                r.embree.hits += embree_hit;
                if (mcrt_hit != embree_hit) {
                    ++r.hit_mismatches;
                } else if (mcrt_hit && triangle != embree_triangle[k]) {
                    ++r.triangle_mismatches;
                    float t = primary_hits[k].x, te = embree_t[k];
                    if (std::abs(t - te) > kTieRelative * std::max(t, te))
                        ++r.triangle_mismatches_apart;
                }
            }
        }
#endif
        if (wanted("primary")) results.push_back(r);
    }

    std::vector<SurfacePoint> points = surface_points(primary, primary_hits, scene.positions);
    for (const char* kind : {"shadow", "ambient"}) {
        if (!wanted(kind)) continue;
        bool shadow = std::strcmp(kind, "shadow") == 0;
        RayBatch rays = shadow ? shadow_rays(frame, points, kShadowSeed)
                               : ambient_rays(frame, points, kAmbientSeed);
        KindResult r;
        r.kind = kind;
        r.count = rays.size();
        std::vector<uint32_t> occluded;
        std::vector<uint8_t> embree_blocked;
        DeviceTracer::Reference reference;
#ifdef MCRT_HAVE_EMBREE
        reference.trace = [&] { embree.occluded(rays, &embree_blocked); };
#endif
        r.mcrt = tracer.any(rays, o.repeats, &occluded, &reference);
#ifdef MCRT_HAVE_EMBREE
        r.has_embree = true;
        r.embree.seconds_median = reference.seconds_median;
        for (size_t k = 0; k < rays.size(); ++k) {
            r.embree.hits += embree_blocked[k];
            r.hit_mismatches += (occluded[k] != 0) != (embree_blocked[k] != 0);
        }
#endif
        results.push_back(r);
    }

    if (o.json) {
        for (const KindResult& r : results) {
            nlohmann::ordered_json j = {
                {"scene", o.scene},
                {"rays", r.kind},
                {"count", r.count},
                {"hits", r.mcrt.hits},
                {"mrays_per_s", r.mcrt.mrays_per_s(r.count)},
                {"seconds_median", r.mcrt.seconds_median},
                {"repeats", o.repeats},
                {"width", o.width},
                {"height", o.height},
                {"device", tracer.info().name},
                {"triangles", scene.triangle_count()},
                {"bvh_build_seconds", bvh.stats.build_seconds},
                {"sah_cost", bvh.stats.sah_cost4},
                {"bvh_depth", bvh.stats.depth4},
                {"bvh_nodes", bvh.nodes4.size()},
                {"bvh_packets", bvh.stats.packets},
                {"bytes_per_triangle", bytes_per_triangle},
            };
#ifdef MCRT_HAVE_EMBREE
            j["embree_mrays_per_s"] = r.embree.mrays_per_s(r.count);
            j["embree_seconds_median"] = r.embree.seconds_median;
            j["embree_hits"] = r.embree.hits;
            j["embree_threads"] = embree.threads();
            j["embree_version"] = embree.version();
            j["embree_build_seconds"] = embree.build_seconds();
            j["hit_mismatches"] = r.hit_mismatches;
            if (r.kind == "primary") {
                j["triangle_mismatches"] = r.triangle_mismatches;
                j["triangle_mismatches_apart"] = r.triangle_mismatches_apart;
            }
#endif
            std::cout << j.dump() << "\n";
        }
        std::cout.flush();
        return 0;
    }

    std::printf("scene %s: %zu triangles, %s camera, %dx%d, device %d: %s\n", o.scene.c_str(),
                scene.triangle_count(),
                o.camera                ? "the --look-from"
                : scene.cameras.empty() ? "bench"
                                        : "its first",
                o.width, o.height, o.device, tracer.info().name.c_str());
    std::printf(
        "mcrt BVH4: built in %.3f s, SAH cost %.2f, depth %d, %zu nodes, %zu packets, %.1f bytes "
        "per triangle\n",
        bvh.stats.build_seconds, bvh.stats.sah_cost4, bvh.stats.depth4, bvh.nodes4.size(),
        bvh.stats.packets, bytes_per_triangle);
#ifdef MCRT_HAVE_EMBREE
    std::printf("Embree %s: built in %.3f s (default quality), %u threads, single-ray API\n",
                embree.version().c_str(), embree.build_seconds(), embree.threads());
#else
    std::printf("Embree: not compiled in (libembree-dev not found at configure time)\n");
#endif
    std::printf(
        "median of %d after a warm-up, launches alternating; mcrt: kernel time from "
        "profiling events, Embree: wall clock\n\n",
        o.repeats);
    std::printf("%-8s %10s %10s %9s", "rays", "count", "hits", "Mrays/s");
#ifdef MCRT_HAVE_EMBREE
    std::printf(" %10s %9s %6s %10s", "Embree hits", "Mrays/s", "ratio", "mismatches");
#endif
    std::printf("\n");
    for (const KindResult& r : results) {
        double mcrt_rate = r.mcrt.mrays_per_s(r.count);
        std::printf("%-8s %10zu %10zu %9.2f", r.kind.c_str(), r.count, r.mcrt.hits, mcrt_rate);
#ifdef MCRT_HAVE_EMBREE
        double embree_rate = r.embree.mrays_per_s(r.count);
        std::printf(" %10zu %9.2f %6.2f %10zu", r.embree.hits, embree_rate,
                    embree_rate > 0 ? mcrt_rate / embree_rate : 0.0, r.hit_mismatches);
        if (r.kind == "primary")
            std::printf("  (+%zu hit another triangle, %zu of them at another distance)",
                        r.triangle_mismatches, r.triangle_mismatches_apart);
#endif
        std::printf("\n");
    }
    return 0;
}

}  // namespace mcrt
