// Intel Embree 3 as the in-run reference of `mcrt bench` (DESIGN.md "Benchmark contract"):
// single-ray rtcIntersect1 / rtcOccluded1 on every core, on the very rays mcrt traces.
// Compiled only when CMake found Embree (MCRT_HAVE_EMBREE).
#pragma once

#ifdef MCRT_HAVE_EMBREE

#include <cstdint>
#include <string>
#include <vector>

#include "bench/bench_rays.h"
#include "scene/scene.h"

typedef struct RTCDeviceTy* RTCDevice;
typedef struct RTCSceneTy* RTCScene;

namespace mcrt {

class EmbreeTracer {
  public:
    // One triangle geometry over every scene triangle (index t = scene triangle t), built at
    // Embree's default quality (RTC_BUILD_QUALITY_MEDIUM). Throws RuntimeError on failure.
    explicit EmbreeTracer(const Scene& scene);
    ~EmbreeTracer();
    EmbreeTracer(const EmbreeTracer&) = delete;
    EmbreeTracer& operator=(const EmbreeTracer&) = delete;

    double build_seconds() const { return build_seconds_; }
    unsigned threads() const { return threads_; }
    std::string version() const;  // "3.13.5"

    // Closest hit of every ray in (0, t_max): the scene triangle index, or UINT32_MAX on a miss;
    // with `t`, also the hit distance (t_max on a miss).
    void closest(const RayBatch& rays, std::vector<uint32_t>* triangle,
                 std::vector<float>* t = nullptr) const;
    // 1 where something blocks the ray in (0, t_max), else 0.
    void occluded(const RayBatch& rays, std::vector<uint8_t>* blocked) const;

  private:
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    double build_seconds_ = 0;
    unsigned threads_ = 1;
};

}  // namespace mcrt

#endif
