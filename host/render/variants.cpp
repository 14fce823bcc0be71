#include "render/variants.h"

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "render/renderer.h"

namespace mcrt {

namespace {

EstimatorVariant reflected(const char* name, const char* function, unsigned uses,
                           const char* description) {
    return {name, function, EstimatorKind::Reflected, uses | kUsesSkyLight, description};
}

EstimatorVariant ambient(const char* name, const char* function, unsigned uses,
                         const char* description) {
    return {name, function, EstimatorKind::Ambient, uses | kUsesSky, description};
}

}  // namespace

// DESIGN.md "Estimators"; the kernel functions are in kernels/estimators/estimators.cl.
const std::vector<EstimatorVariant> kEstimatorVariants = {
    reflected("hemisphere-uniform", "estimate_hemisphere_uniform", kUsesLights,
              "directions uniform on the hemisphere, pdf 1/(2 pi), counting the emitters they "
              "hit (GI Compendium eq. 34)"),
    reflected("hemisphere-cosine", "estimate_hemisphere_cosine", kUsesLights,
              "cosine-weighted directions, pdf cos/pi, counting the emitters they hit (eq. 35)"),
    reflected("bsdf", "estimate_bsdf", kUsesLights | kUsesBsdfSampling,
              "directions by the BSDF's sampling density (cosine for Lambertian, GGX visible "
              "normals for glossy lobes), counting the emitters they hit"),
    reflected("light-area", "estimate_light_area", kUsesLights | kUsesLightSelection,
              "a light by --light-select and a uniform point on it, pdf pmf/area converted by "
              "cos_y/d^2"),
    reflected("light-solid-angle", "estimate_light_solid_angle", kUsesLights | kUsesLightSelection,
              "a light by --light-select and a direction uniform in its spherical triangle (Arvo "
              "1995), area below 3e-4 sr"),
    reflected("mis", "estimate_mis",
              kUsesLights | kUsesLightSelection | kUsesMisHeuristic | kUsesBsdfSampling,
              "one light-area and one BSDF-sampled direction, weighted by --mis-heuristic (Veach "
              "1997)"),
    ambient("ambient-uniform", "estimate_ambient_uniform", 0,
            "ambient light: sky visibility over uniform directions, albedo x L_sky x (1/pi) int "
            "V cos"),
    ambient("ambient-cosine", "estimate_ambient_cosine", 0,
            "ambient light: sky visibility over cosine-weighted directions"),
    ambient("ambient-fibonacci", "estimate_ambient_fibonacci", kUsesCorrelatedSamples,
            "ambient light: sky visibility over a perturbed spherical Fibonacci spiral of spp "
            "points"),
};

const std::vector<LightSelectVariant> kLightSelectVariants = {
    {"uniform", LightSelection::Uniform, "LIGHT_SELECT_UNIFORM",
     "every light with probability 1/lights"},
    {"power", LightSelection::Power, "LIGHT_SELECT_POWER",
     "in proportion to emitted power, CDF inversion by binary search (PBRT 13.3.1), on the 2^-24 "
     "grid"},
    {"alias", LightSelection::Alias, "LIGHT_SELECT_ALIAS",
     "the power distribution by an alias table (Vose 1991), O(1)"},
    {"tree", LightSelection::Tree, "LIGHT_SELECT_TREE",
     "a light tree (SAOH-built BVH with orientation cones): power x distance x orientation at the "
     "shading point (Conty Estevez & Kulla 2018; pbrt-v4 BVHLightSampler)"},
};

const std::vector<SamplerVariant> kSamplerVariants = {
    {"independent", Sampler::Independent, "SAMPLER_INDEPENDENT", false,
     "independent uniform numbers, pcg4d of (pixel, sample, dimension, seed)"},
    {"stratified", Sampler::Stratified, "SAMPLER_STRATIFIED", true,
     "jittered strata per dimension pair, permuted per pixel (Kensler 2013)"},
    {"sobol", Sampler::Sobol, "SAMPLER_SOBOL", true,
     "Owen-scrambled Sobol' pairs, padded by shuffling (Burley 2020)"},
};

const std::vector<MisHeuristicVariant> kMisHeuristicVariants = {
    {"balance", MisHeuristic::Balance, "MIS_BALANCE", "w_a = p_a / (p_a + p_b)"},
    {"power", MisHeuristic::Power, "MIS_POWER", "w_a = p_a^2 / (p_a^2 + p_b^2), beta = 2"},
};

const std::vector<MaterialVariant> kMaterialVariants = {
    {"gltf", MaterialModel::Gltf, "MCRT_MATERIALS_GLTF", false,
     "glTF 2.0 metallic-roughness (Appendix B: GGX, height-correlated Smith, Schlick; "
     "KHR_materials_specular), as the file says"},
    {"lambert", MaterialModel::Lambert, nullptr, true,
     "every surface Lambertian, baseColor/pi (the course's model)"},
};

EstimatorVariant user_estimator_variant() {
    return reflected("file", kUserEstimatorFunction,
                     kUsesLights | kUsesLightSelection | kUsesMisHeuristic,
                     "a user's estimator file (docs/ESTIMATORS.md)");
}

namespace {

template <typename Row>
std::string accepted(const std::vector<Row>& table) {
    std::string names;
    for (const Row& row : table) names += (names.empty() ? "" : ", ") + std::string(row.name);
    return names;
}

// The row named `name` of `table`; SettingError naming `setting` otherwise.
template <typename Row>
const Row& find_row(const std::vector<Row>& table, const std::string& name, const char* setting,
                    const char* what) {
    for (const Row& row : table)
        if (name == row.name) return row;
    throw SettingError(setting, name + ": unknown " + what + " (one of " + accepted(table) + ")");
}

}  // namespace

RenderVariants resolve_variants(const RenderSettings& settings) {
    RenderVariants v;
    v.estimator = settings.estimator_file.empty()
                      ? find_row(kEstimatorVariants, settings.estimator, "estimator", "estimator")
                      : user_estimator_variant();
    v.light_select =
        &find_row(kLightSelectVariants, settings.light_select, "light_select", "light selection");
    v.sampler = &find_row(kSamplerVariants, settings.sampler, "sampler", "sampler");
    v.mis_heuristic =
        &find_row(kMisHeuristicVariants, settings.mis_heuristic, "mis_heuristic", "heuristic");
    v.materials = &find_row(kMaterialVariants, settings.materials, "materials", "material model");
    return v;
}

std::string variant_program_options(const RenderVariants& v, bool microfacet, bool textured,
                                    bool transmission, bool single_sided, bool environment_map,
                                    bool punctual) {
    std::string options = std::string("-cl-std=CL1.2 -D MCRT_ESTIMATE=") + v.estimator.function;
    if (v.ambient()) options += " -D MCRT_AMBIENT_ESTIMATOR";
    options += std::string(" -D ") + v.light_select->macro;
    options += std::string(" -D ") + v.sampler->macro;
    // Estimators that weigh no strategies all build with the first heuristic: one program
    // whatever --mis-heuristic says.
    options += std::string(" -D ") + (v.uses(kUsesMisHeuristic) ? v.mis_heuristic->macro
                                                                : kMisHeuristicVariants[0].macro);
    if (microfacet && v.materials->macro) options += std::string(" -D ") + v.materials->macro;
    // Texture lookups and alpha tests only for a scene that has them (DESIGN.md "Radiometric
    // contract": model no more than a scene needs).
    if (textured) options += " -D MCRT_TEXTURES";
    // Glass only for a scene that has it, and only in the glTF model (--materials lambert makes
    // every surface opaque).
    if (transmission && microfacet && v.materials->macro) options += " -D MCRT_TRANSMISSION";
    // Back-face culling only for a scene with a single-sided, non-transmissive triangle.
    if (single_sided) options += " -D MCRT_SINGLE_SIDED";
    // Texel lookups and the map's 2D distribution only for a render with --env.
    if (environment_map) options += " -D MCRT_ENVIRONMENT_MAP";
    // Punctual lights only for a scene that has them, and only for estimators that can sample
    // them (a light selection's strategies); the others cannot see them (DESIGN.md).
    if (punctual && v.uses(kUsesLightSelection)) options += " -D MCRT_PUNCTUAL";
    return options;
}

std::vector<std::string> uses_names(unsigned uses) {
    std::vector<std::string> names;
    if (uses & kUsesLights) names.push_back("lights");
    if (uses & kUsesLightSelection) names.push_back("light-selection");
    if (uses & kUsesSky) names.push_back("sky");
    if (uses & kUsesMisHeuristic) names.push_back("mis-heuristic");
    if (uses & kUsesBsdfSampling) names.push_back("bsdf-sampling");
    if (uses & kUsesCorrelatedSamples) names.push_back("correlated-samples");
    if (uses & kUsesSkyLight) names.push_back("sky-light");
    return names;
}

namespace {

const char* kind_name(EstimatorKind kind) {
    return kind == EstimatorKind::Ambient ? "ambient" : "reflected";
}

template <typename Row>
nlohmann::json option_rows(const std::vector<Row>& table) {
    nlohmann::json rows = nlohmann::json::array();
    for (const Row& row : table)
        rows.push_back({{"name", row.name},
                        {"macro", row.macro ? nlohmann::json(row.macro) : nlohmann::json()},
                        {"description", row.description}});
    return rows;
}

template <typename Row>
void option_lines(std::string& out, const char* title, const std::vector<Row>& table) {
    out += title;
    for (const Row& row : table)
        out += "  " + std::string(row.name) + std::string(20 - std::string(row.name).size(), ' ') +
               row.description + (row.macro ? " [-D " + std::string(row.macro) + "]" : "") + "\n";
}

}  // namespace

std::string variants_json() {
    nlohmann::json estimators = nlohmann::json::array();
    for (const EstimatorVariant& row : kEstimatorVariants)
        estimators.push_back({{"name", row.name},
                              {"function", row.function},
                              {"kind", kind_name(row.kind)},
                              {"uses", uses_names(row.uses)},
                              {"description", row.description}});
    const EstimatorVariant user = user_estimator_variant();
    nlohmann::json j = {{"estimators", estimators},
                        {"light_select", option_rows(kLightSelectVariants)},
                        {"samplers", option_rows(kSamplerVariants)},
                        {"mis_heuristics", option_rows(kMisHeuristicVariants)},
                        {"materials", option_rows(kMaterialVariants)},
                        {"user_estimator",
                         {{"function", user.function},
                          {"kind", kind_name(user.kind)},
                          {"uses", uses_names(user.uses)}}}};
    return j.dump(2) + "\n";
}

std::string variants_text() {
    std::string out = "estimators (--estimator):\n";
    for (const EstimatorVariant& row : kEstimatorVariants) {
        std::string uses;
        for (const std::string& u : uses_names(row.uses)) uses += (uses.empty() ? "" : ",") + u;
        out += "  " + std::string(row.name) + std::string(20 - std::string(row.name).size(), ' ') +
               row.description + " [" + kind_name(row.kind) + "; uses " + uses + "; " +
               row.function + "]\n";
    }
    option_lines(out, "light selection (--light-select):\n", kLightSelectVariants);
    option_lines(out, "samplers (--sampler):\n", kSamplerVariants);
    option_lines(out, "MIS heuristics (--mis-heuristic; only for estimators that use one):\n",
                 kMisHeuristicVariants);
    option_lines(out,
                 "materials (--materials; the macro only for a scene that is not all "
                 "Lambertian):\n",
                 kMaterialVariants);
    out += "a user's estimator (--estimator-file FILE.cl) defines float3 " +
           std::string(kUserEstimatorFunction) + "(...): docs/ESTIMATORS.md\n";
    return out;
}

}  // namespace mcrt
