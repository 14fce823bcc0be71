#include "render/render_program.h"

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "common/error.h"
#include "common/test_hooks.h"
#include "render/renderer.h"
#include "render/variants.h"
#include "shared_types.h"

namespace mcrt {

float sky_light_pmf(const RenderSettings& settings, uint32_t light_count) {
    if (!settings.sky_light) return 0.0f;
    return light_count > 0 ? 0.5f : 1.0f;
}

std::string render_program_options(const RenderSettings& settings, bool microfacet) {
    std::string options = "-cl-std=CL1.2";
    unsigned uses = kUserEstimatorUses;
    if (settings.max_depth > MCRT_MAX_PATH_DEPTH)
        throw InputError("--max-depth " + std::to_string(settings.max_depth) + ": at most " +
                         std::to_string(MCRT_MAX_PATH_DEPTH));
    if (settings.rr_depth < 1 || settings.rr_depth > MCRT_MAX_PATH_DEPTH)
        throw InputError("--rr-depth " + std::to_string(settings.rr_depth) + ": expected 1 .. " +
                         std::to_string(MCRT_MAX_PATH_DEPTH));
    if (settings.estimator_file.empty()) {
        const EstimatorVariant& estimator = estimator_variant(settings.estimator);
        options += std::string(" -D MCRT_ESTIMATE=") + estimator.function;
        uses = estimator.uses;
        // The ambient estimators integrate sky visibility, not reflected light: no path to extend.
        if ((uses & kUsesSky) && settings.max_depth > 1)
            throw InputError("--max-depth " + std::to_string(settings.max_depth) +
                             ": --estimator " + settings.estimator +
                             " is an ambient estimator (sky visibility, one bounce): --max-depth "
                             "0 or 1; path tracing under the sky is --sky R,G,B with light-area, "
                             "light-solid-angle, bsdf, hemisphere-* or mis");
        if (uses & kUsesSky) options += " -D ESTIMATOR_USES_SKY";
    } else {
        options += std::string(" -D MCRT_ESTIMATE=") + kUserEstimatorFunction;
    }
    options += std::string(" -D ") +
               option_variant(kLightSelectVariants, settings.light_select, "--light-select").macro;
    options +=
        std::string(" -D ") + option_variant(kSamplerVariants, settings.sampler, "--sampler").macro;
    const OptionVariant& heuristic =
        option_variant(kMisHeuristicVariants, settings.mis_heuristic, "--mis-heuristic");
    if ((uses & kUsesMisHeuristic) && heuristic.macro)
        options += std::string(" -D ") + heuristic.macro;
    const OptionVariant& materials =
        option_variant(kMaterialVariants, settings.materials, "--materials");
    if (microfacet && materials.macro) options += std::string(" -D ") + materials.macro;
    // Development override, as MCRT_KERNEL_DIR is for the sources: extra build options, e.g.
    // the -D switches of scripts/bench/profile_stages.py (docs/BENCHMARKS.md, "Where a sample's time goes").
    if (const char* extra = std::getenv("MCRT_KERNEL_OPTIONS"); extra && *extra)
        options += std::string(" ") + extra;
    return options;
}

KernelReplacements render_program_replacements(const RenderSettings& settings) {
    if (settings.estimator_file.empty()) return {};
    return {{"user_estimator.cl", {settings.estimator_file, settings.estimator_source}}};
}

namespace {

// The first error the build log reports in `file`, as "FILE:LINE: message", from clang's
// "FILE:LINE:COLUMN: error: message" (PoCL prefixes "error: "); "" when the log names none.
std::string first_error_in(const std::string& log, const std::string& file) {
    std::istringstream in(log);
    std::string line;
    const std::string prefix = file + ":";
    while (std::getline(in, line)) {
        size_t at = line.find(prefix);
        if (at == std::string::npos || line.find("error") == std::string::npos) continue;
        size_t digits = at + prefix.size(), end = digits;
        while (end < line.size() && std::isdigit(static_cast<unsigned char>(line[end]))) ++end;
        if (end == digits) continue;
        // The message after "LINE:COLUMN: ".
        size_t message = line.find(": ", end);
        std::string text = message == std::string::npos ? line : line.substr(message + 2);
        if (text.rfind("error: ", 0) == 0) text = text.substr(7);
        return prefix + line.substr(digits, end - digits) + ": " + text;
    }
    return "";
}

}  // namespace

cl::Program render_program(const DeviceContext& device, const RenderSettings& settings,
                           bool microfacet) {
    try {
        std::string options = render_program_options(settings, microfacet);
        if (test_wrong_device(device.info.index)) options += " -D MCRT_TEST_WRONG_VALUES";
        return cached_program(device, "render.cl", options, render_program_replacements(settings));
    } catch (const RuntimeError& e) {
        if (settings.estimator_file.empty()) throw;
        std::string what = e.what();
        std::string error =
            first_error_in(what.substr(what.find('\n') + 1), settings.estimator_file);
        if (error.empty()) throw;
        throw InputError(error + " (--estimator-file; build log follows)\n" +
                         what.substr(what.find('\n') + 1));
    }
}

std::string read_estimator_file(const std::string& path) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status))
        throw InputError("--estimator-file " + path + ": no such file");
    if (!std::filesystem::is_regular_file(status))
        throw InputError("--estimator-file " + path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) throw InputError("--estimator-file " + path + ": cannot read");
    // The kernel calls the user's function by name: say so before a compiler would, in mcrt's
    // own source, that it is missing.
    static const std::regex definition(std::string("\\b") + kUserEstimatorFunction + "\\s*\\(");
    if (!std::regex_search(text.str(), definition))
        throw InputError("--estimator-file " + path + ": defines no function float3 " +
                         kUserEstimatorFunction +
                         "(const SceneView*, const SurfacePoint*, "
                         "const SampleStream*, uint*) (docs/ESTIMATORS.md)");
    return text.str();
}

}  // namespace mcrt
