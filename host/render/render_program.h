// The render program of a render's plan: its -D options (RenderPlan::program_options), a user's
// estimator file in place of kernels/estimators/user_estimator.cl (checked by
// render/estimator_file.h), and its build on one device.
#pragma once

#include <CL/opencl.hpp>
#include <cstdint>
#include <string>

#include "cl/device.h"
#include "cl/program.h"

namespace mcrt {

struct RenderSettings;
struct RenderPlan;

// Probability that the light strategies choose the sky light (RenderParams::sky.w): 0 when the
// sky is no light, 1 when it is the only one, else 1/2 beside the area lights, the exact split of
// the selection sample (kernels/lights/light_sampling.cl, select_sky).
float sky_light_pmf(const RenderSettings& settings, uint32_t light_count);

// The user's estimator file, if any, as the replacement of kernels/estimators/user_estimator.cl.
KernelReplacements render_program_replacements(const RenderSettings& settings);

// The render program built (once per process) for the device. A build error in a user's
// estimator file throws InputError whose first line names FILE:LINE and the compiler's message,
// followed by the build log; any other build failure throws RuntimeError with the log.
cl::Program render_program(const DeviceContext& device, const RenderPlan& plan);

}  // namespace mcrt
