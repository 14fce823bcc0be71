// Every estimator, light selection, sampler and MIS heuristic, each one row of one table: the
// name the command line, the stats and the scripts use; the kernel option it compiles to,
// written out in full; what it uses; one line of description. The CLI's validation and --help,
// the kernel options, `mcrt variants --json` (read by the scripts) and the tests read these
// tables; adding a built-in estimator is one kernel function plus one row (docs/ESTIMATORS.md).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace mcrt {

// What an estimator uses, as bits of EstimatorVariant::uses.
enum EstimatorUses : unsigned {
    kUsesLights = 1u << 0,          // samples or hits emissive triangles (warn when there are none)
    kUsesLightSelection = 1u << 1,  // chooses among the lights with --light-select
    kUsesSky = 1u << 2,           // sees the uniform sky (--sky, --ao-distance); camera misses too
    kUsesMisHeuristic = 1u << 3,  // weights strategies with --mis-heuristic
    kUsesBsdfSampling = 1u << 4,  // draws directions from the BSDF
    kUsesCorrelatedSamples = 1u << 5,  // a pixel's samples are correlated whatever the sampler
                                       // (the Fibonacci spiral): error bars need replicates
    kUsesSkyLight = 1u << 6,  // with --sky, sees the sky as a light at infinity (its directions
                              // that escape, the light strategies' sky samples); paths
};

struct EstimatorVariant {
    const char* name;      // --estimator
    const char* function;  // the kernel function, compiled in as -D MCRT_ESTIMATE=<function>
    unsigned uses;         // EstimatorUses bits
    const char* description;
};

// A light selection, sampler or MIS heuristic: a -D option of the kernels.
struct OptionVariant {
    const char* name;   // --light-select, --sampler, --mis-heuristic
    const char* macro;  // the -D option it compiles to; nullptr: none (the kernels' default)
    const char* description;
};

// Globals of variants.cpp: read them at run time, not from other files' static initializers.
extern const std::vector<EstimatorVariant> kEstimatorVariants;
extern const std::vector<OptionVariant> kLightSelectVariants;
extern const std::vector<OptionVariant> kSamplerVariants;
extern const std::vector<OptionVariant> kMisHeuristicVariants;
// --materials: the macro is defined only when the scene has a surface that is not Lambertian
// (GpuSceneData::microfacet), so a Lambertian scene's kernels are the course's.
extern const std::vector<OptionVariant> kMaterialVariants;

// The row named `name`; throws InputError naming `option` and the accepted names.
const EstimatorVariant& estimator_variant(const std::string& name);
const OptionVariant& option_variant(const std::vector<OptionVariant>& table,
                                    const std::string& name, const char* option);

// True for the light selection that reads the light tree (make_gpu_scene builds it only then).
bool light_select_uses_tree(const std::string& name);

// The rows' names, in table order (CLI11's IsMember, --help, the tests).
std::vector<std::string> variant_names(const std::vector<EstimatorVariant>& table);
std::vector<std::string> variant_names(const std::vector<OptionVariant>& table);

// Names of the `uses` bits, for --help, the stats and `mcrt variants`.
std::vector<std::string> uses_names(unsigned uses);

// What a user's --estimator-file is assumed to use: lights, their selection and the MIS
// heuristic (it may call mis_weight), the sky light (through the light strategies and
// environment_radiance); the ambient sky only when the file defines ESTIMATOR_USES_SKY
// (docs/ESTIMATORS.md).
constexpr unsigned kUserEstimatorUses =
    kUsesLights | kUsesLightSelection | kUsesMisHeuristic | kUsesSkyLight;

// The function a user's estimator file defines.
constexpr const char* kUserEstimatorFunction = "estimate";

// Replicates the variance layer is estimated from when the sampler (or the estimator) correlates
// a pixel's samples and --replicates is not given: the trade-off between the error bar's own
// noise and the QMC efficiency that splitting loses is measured in docs/EXPERIMENTS.md.
constexpr unsigned kDefaultReplicates = 2;

// Every table as JSON text (`mcrt variants --json`).
std::string variants_json();

// Every table as aligned text (`mcrt variants`).
std::string variants_text();

}  // namespace mcrt
