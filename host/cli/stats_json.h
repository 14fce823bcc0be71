// The stats JSON of `mcrt render --stats` (DESIGN.md "Outputs"), plus BVH and timing details.
#pragma once

#include <nlohmann/json.hpp>

#include "bvh/bvh.h"
#include "cli/render_command.h"
#include "render/gpu_scene.h"
#include "render/plan.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace mcrt {

struct RenderStatsInput {
    const RenderOptions& options;
    const RenderPlan& plan;
    const PreparedScene& scene;  // as the plan's render saw it
    const RenderResult& result;
    double seconds_total = 0;
    double seconds_to_render = 0;  // from the command's start to render(): load, BVH, upload
};

nlohmann::json render_stats_json(const RenderStatsInput& in);

}  // namespace mcrt
