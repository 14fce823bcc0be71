// `mcrt bench`: times BVH ray queries alone on the rays of DESIGN.md's benchmark contract, and
// the same rays traced by Embree in the same run when it was found at configure time.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "bvh/bvh.h"
#include "scene/scene.h"

namespace mcrt {

struct BenchOptions {
    std::string scene;
    std::string rays;  // "primary", "shadow", "ambient"; empty: all three
    int width = 1024, height = 1024;
    int repeats = 5;               // timed launches after one warm-up; the median is reported
    int device = 0;                // index from `mcrt devices`
    bool json = false;             // one JSON object per ray kind and line instead of a table
    BvhBuildOptions bvh;           // SAH build options, for experiments with the tree's shape
    std::optional<Camera> camera;  // --look-from ...: in place of the scene's camera
};

// Runs the benchmark and prints its results on stdout; returns the exit status. Throws
// InputError (bad scene, no such device index) or RuntimeError (OpenCL, Embree failures).
int run_bench(const BenchOptions& options, const std::function<void(const std::string&)>& warn);

}  // namespace mcrt
