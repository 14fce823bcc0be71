#include "render/render_program.h"

#include "common/environment.h"
#include "common/error.h"
#include "common/test_hooks.h"
#include "render/estimator_file.h"
#include "render/plan.h"
#include "render/renderer.h"

namespace mcrt {

float sky_light_pmf(const RenderSettings& settings, uint32_t light_count) {
    if (!settings.sky_light) return 0.0f;
    return light_count > 0 ? 0.5f : 1.0f;
}

KernelReplacements render_program_replacements(const RenderSettings& settings) {
    if (settings.estimator_file.empty()) return {};
    return {{"user_estimator.cl", {settings.estimator_file, settings.estimator_source}}};
}

cl::Program render_program(const DeviceContext& device, const RenderPlan& plan) {
    const RenderSettings& settings = plan.settings;
    try {
        std::string options = plan.program_options;
        // Development override, as MCRT_KERNEL_DIR is for the sources: extra build options, e.g.
        // the -D switches of the stage profiler (docs/BENCHMARKS.md).
        if (const std::string extra = environment_value(kEnvKernelOptions); !extra.empty())
            options += " " + extra;
        if (test_wrong_device(device.info.index)) options += " -D MCRT_TEST_WRONG_VALUES";
        return cached_program(device, "render.cl", options, render_program_replacements(settings));
    } catch (const RuntimeError& e) {
        if (settings.estimator_file.empty()) throw;
        std::string what = e.what();
        const std::string log = what.substr(what.find('\n') + 1);
        const std::string error =
            estimator_build_error(log, settings.estimator_file, settings.estimator_source);
        if (error.empty()) throw;
        throw InputError(error + " (the estimator file; build log follows)\n" +
                         what.substr(what.find('\n') + 1));
    }
}

}  // namespace mcrt
