// Every estimator, light selection, sampler, MIS heuristic and material build, each one row of
// one table: the name the command line, the stats and the scripts use; what it is as an enum;
// the kernel option it compiles to, written out in full; what it implies; one line of
// description. resolve_variants() turns a render's names into rows once (render/plan.h); the
// CLI's validation and --help, the kernel options, `mcrt variants --json` (read by the scripts)
// and the tests read these tables. Adding a built-in estimator is one kernel function plus one
// row (docs/ESTIMATORS.md); a light selection or material model, docs/DESIGN.md "Variants".
#pragma once

#include <string>
#include <vector>

namespace mcrt {

struct RenderSettings;  // render/renderer.h

// What an estimator uses, as bits of EstimatorVariant::uses.
enum EstimatorUses : unsigned {
    kUsesLights = 1u << 0,          // samples or hits emissive triangles (warn when there are none)
    kUsesLightSelection = 1u << 1,  // chooses among the lights with --light-select
    kUsesSky = 1u << 2,  // sees the uniform sky (--sky, --ao-distance); camera misses too. Set by
                         // the ambient kind, never by hand
    kUsesMisHeuristic = 1u << 3,       // weights strategies with --mis-heuristic
    kUsesBsdfSampling = 1u << 4,       // draws directions from the BSDF
    kUsesCorrelatedSamples = 1u << 5,  // a pixel's samples are correlated whatever the sampler
                                       // (the Fibonacci spiral): error bars need replicates
    kUsesSkyLight = 1u << 6,  // with --sky, sees the sky as a light at infinity (its directions
                              // that escape, the light strategies' sky samples); paths. Set by
                              // the reflected kind, never by hand
};

// What an estimator integrates. Reflected: the direct light reflected at a surface point, which
// a path extends (--max-depth) and under --sky sees the sky as a light. Ambient: sky visibility
// (the course's ambient light), one bounce, the sky seen by camera rays that miss; compiled with
// -D MCRT_AMBIENT_ESTIMATOR.
enum class EstimatorKind { Reflected, Ambient };

struct EstimatorVariant {
    const char* name;      // --estimator
    const char* function;  // the kernel function, compiled in as -D MCRT_ESTIMATE=<function>
    EstimatorKind kind;
    unsigned uses;  // EstimatorUses bits, the kind's sky bit included
    const char* description;
};

enum class LightSelection { Uniform, Power, Alias, Tree };
enum class Sampler { Independent, Stratified, Sobol };
enum class MisHeuristic { Balance, Power };
enum class MaterialModel { Gltf, Lambert };

// A light selection (--light-select). Its data (power's CDF, alias's table, the tree) is built
// and uploaded only for it (make_gpu_scene).
struct LightSelectVariant {
    const char* name;
    LightSelection id;
    const char* macro;  // the -D option it compiles to
    const char* description;
};

// A sample generator (--sampler).
struct SamplerVariant {
    const char* name;
    Sampler id;
    const char* macro;
    bool correlated;  // a pixel's samples are not independent: error bars need replicates
    const char* description;
};

// An MIS heuristic (--mis-heuristic); compiled only for estimators that use one.
struct MisHeuristicVariant {
    const char* name;
    MisHeuristic id;
    const char* macro;
    const char* description;
};

// How the scene's surfaces are read (--materials).
struct MaterialVariant {
    const char* name;
    MaterialModel id;
    // The -D option for a scene with a surface that is not Lambertian (GpuSceneData::microfacet),
    // so a Lambertian scene's kernels are the course's; nullptr: never (every surface Lambertian).
    const char* macro;
    bool lambertian;  // every surface is made Lambertian (baseColor/π) when the scene is read
    const char* description;
};

// Globals of variants.cpp: read them at run time, not from other files' static initializers.
extern const std::vector<EstimatorVariant> kEstimatorVariants;
extern const std::vector<LightSelectVariant> kLightSelectVariants;
extern const std::vector<SamplerVariant> kSamplerVariants;
extern const std::vector<MisHeuristicVariant> kMisHeuristicVariants;
extern const std::vector<MaterialVariant> kMaterialVariants;

// The function a user's estimator file defines, and the row it renders as: a reflected-light
// estimator that uses lights, their selection and the MIS heuristic (it may call mis_weight),
// and the sky light (docs/ESTIMATORS.md).
constexpr const char* kUserEstimatorFunction = "estimate";
EstimatorVariant user_estimator_variant();

// A render's variants, resolved from its names once (render/plan.h), with what they imply.
struct RenderVariants {
    EstimatorVariant estimator;  // the built-in row, or user_estimator_variant's
    const LightSelectVariant* light_select = nullptr;
    const SamplerVariant* sampler = nullptr;
    const MisHeuristicVariant* mis_heuristic = nullptr;
    const MaterialVariant* materials = nullptr;

    bool uses(unsigned bits) const { return (estimator.uses & bits) == bits; }
    bool ambient() const { return estimator.kind == EstimatorKind::Ambient; }
    // A pixel's samples are correlated (the sampler or the estimator): the variance layer is
    // estimated from replicates by default.
    bool correlated() const { return sampler->correlated || uses(kUsesCorrelatedSamples); }
};

// The rows the settings name; throws SettingError (render/plan.h) naming the setting and the
// accepted names.
RenderVariants resolve_variants(const RenderSettings& settings);

// The -D options of the render program for these variants; `microfacet`: the scene has a
// surface that is not Lambertian; `textured`: a material with a texture or alpha test
// (-D MCRT_TEXTURES); `transmission`: a transmissive material (-D MCRT_TRANSMISSION, with the
// glTF model only); `single_sided`: a triangle whose back face is culled (-D MCRT_SINGLE_SIDED);
// `environment_map`: a render with --env (-D MCRT_ENVIRONMENT_MAP); `punctual`: KHR_lights_punctual
// lights (-D MCRT_PUNCTUAL).
std::string variant_program_options(const RenderVariants& variants, bool microfacet, bool textured,
                                    bool transmission = false, bool single_sided = false,
                                    bool environment_map = false, bool punctual = false);

// The rows' names, in table order (CLI11's IsMember, --help, the tests).
template <typename Row>
std::vector<std::string> variant_names(const std::vector<Row>& table) {
    std::vector<std::string> names;
    for (const Row& row : table) names.push_back(row.name);
    return names;
}

// Names of the `uses` bits, for --help, the stats and `mcrt variants`.
std::vector<std::string> uses_names(unsigned uses);

// Replicates the variance layer is estimated from when the sampler (or the estimator) correlates
// a pixel's samples and --replicates is not given: the trade-off between the error bar's own
// noise and the QMC efficiency that splitting loses is measured in docs/EXPERIMENTS.md.
constexpr unsigned kDefaultReplicates = 2;

// Every table as JSON text (`mcrt variants --json`).
std::string variants_json();

// Every table as aligned text (`mcrt variants`).
std::string variants_text();

}  // namespace mcrt
