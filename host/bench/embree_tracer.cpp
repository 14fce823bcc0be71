#ifdef MCRT_HAVE_EMBREE

#include "bench/embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "common/error.h"

namespace mcrt {
namespace {

// Rays per work item handed to a thread: small enough to balance uneven rays, large enough that
// the shared counter is no cost.
constexpr size_t kChunk = 4096;

// Runs body(begin, end) over [0, n) in chunks on `threads` std::threads (dynamic scheduling).
template <typename Body>
void parallel_chunks(size_t n, unsigned threads, const Body& body) {
    std::atomic<size_t> next{0};
    auto worker = [&] {
        for (;;) {
            size_t begin = next.fetch_add(kChunk);
            if (begin >= n) return;
            body(begin, std::min(n, begin + kChunk));
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
}

std::string device_error(RTCDevice device) {
    switch (rtcGetDeviceError(device)) {
        case RTC_ERROR_NONE:
            return "no error";
        case RTC_ERROR_INVALID_ARGUMENT:
            return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION:
            return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY:
            return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU:
            return "unsupported CPU";
        case RTC_ERROR_CANCELLED:
            return "cancelled";
        default:
            return "unknown error";
    }
}

// Embree's ray layout (rtcore_ray.h) from trace.cl's: [tnear, tfar] = [0, t_max].
void fill_ray(RTCRay* ray, const gpu::float4& o, const gpu::float4& d) {
    ray->org_x = o.x;
    ray->org_y = o.y;
    ray->org_z = o.z;
    ray->tnear = 0.0f;
    ray->dir_x = d.x;
    ray->dir_y = d.y;
    ray->dir_z = d.z;
    ray->time = 0.0f;
    ray->tfar = o.w;
    ray->mask = 0xffffffffu;
    ray->id = 0;
    ray->flags = 0;
}

}  // namespace

EmbreeTracer::EmbreeTracer(const Scene& scene) {
    threads_ = std::max(1u, std::thread::hardware_concurrency());
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw RuntimeError("Embree: rtcNewDevice failed");
    auto start = std::chrono::steady_clock::now();
    scene_ = rtcNewScene(device_);
    size_t n = scene.triangle_count();
    if (n > 0) {
        RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Buffers Embree allocates itself are padded as its SIMD loads need
        // (rtcSetNewGeometryBuffer).
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
        auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), n));
        if (!vertices || !indices) {
            rtcReleaseGeometry(geometry);
            throw RuntimeError("Embree: cannot allocate buffers: " + device_error(device_));
        }
        static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "Scene positions are packed floats");
        std::memcpy(vertices, scene.positions.data(), 3 * n * 3 * sizeof(float));
        for (uint32_t k = 0; k < 3 * n; ++k) indices[k] = k;
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene_, geometry);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE)
        throw RuntimeError("Embree: scene build failed: " + device_error(device_));
    build_seconds_ =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string EmbreeTracer::version() const {
    // RTC_DEVICE_PROPERTY_VERSION is major·10000 + minor·100 + patch (rtcGetDeviceProperty).
    ssize_t v = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION);
    return std::to_string(v / 10000) + "." + std::to_string(v / 100 % 100) + "." +
           std::to_string(v % 100);
}

EmbreeTracer::~EmbreeTracer() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

void EmbreeTracer::closest(const RayBatch& rays, std::vector<uint32_t>* triangle,
                           std::vector<float>* t) const {
    triangle->resize(rays.size());
    if (t) t->resize(rays.size());
    parallel_chunks(rays.size(), threads_, [&](size_t begin, size_t end) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (size_t k = begin; k < end; ++k) {
            RTCRayHit rh;
            fill_ray(&rh.ray, rays.origins[k], rays.directions[k]);
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene_, &context, &rh);
            (*triangle)[k] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? UINT32_MAX : rh.hit.primID;
            if (t) (*t)[k] = rh.ray.tfar;
        }
    });
}

void EmbreeTracer::occluded(const RayBatch& rays, std::vector<uint8_t>* blocked) const {
    blocked->resize(rays.size());
    parallel_chunks(rays.size(), threads_, [&](size_t begin, size_t end) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (size_t k = begin; k < end; ++k) {
            RTCRay ray;
            fill_ray(&ray, rays.origins[k], rays.directions[k]);
            rtcOccluded1(scene_, &context, &ray);
            // rtcOccluded1 sets tfar to -inf when the ray is blocked (rtcOccluded1 man page).
            (*blocked)[k] = ray.tfar < 0.0f ? 1 : 0;
        }
    });
}

}  // namespace mcrt

#endif
