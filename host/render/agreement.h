// The agreement check of a render's local devices before their samples enter the image
// (docs/DESIGN.md, "Determinism"): the scheduler (renderer.cpp) runs it once per render.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/render_worker.h"
#include "render/renderer.h"

namespace mcrt {

// No device is trusted blindly: the local devices (the first `count` workers) each render the
// agreement item, and their sums must agree bit for bit, as the kernels' arithmetic promises
// (docs/DESIGN.md, "Determinism"). The largest group that agrees stays (among equals, the one
// holding the earliest device); every other device is retired with one warning naming it and
// the first value that differs. A device whose launch fails here is retired as it would be later.
void check_agreement(std::vector<std::unique_ptr<RenderWorker>>& workers, size_t count,
                     const RenderSettings& settings,
                     const std::function<void(const std::string&)>& warn);

}  // namespace mcrt
