#include "render/variants.h"

#include <nlohmann/json.hpp>

#include "common/error.h"

namespace mcrt {

// DESIGN.md "Estimators"; the kernel functions are in kernels/estimators.cl.
const std::vector<EstimatorVariant> kEstimatorVariants = {
    {"hemisphere-uniform", "estimate_hemisphere_uniform", kUsesLights | kUsesSkyLight,
     "directions uniform on the hemisphere, pdf 1/(2 pi), counting the emitters they hit (GI "
     "Compendium eq. 34)"},
    {"hemisphere-cosine", "estimate_hemisphere_cosine", kUsesLights | kUsesSkyLight,
     "cosine-weighted directions, pdf cos/pi, counting the emitters they hit (eq. 35)"},
    {"bsdf", "estimate_bsdf", kUsesLights | kUsesBsdfSampling | kUsesSkyLight,
     "directions by the BSDF's sampling density (cosine for Lambertian, GGX visible normals for "
     "glossy lobes), counting the emitters they hit"},
    {"light-area", "estimate_light_area", kUsesLights | kUsesLightSelection | kUsesSkyLight,
     "a light by --light-select and a uniform point on it, pdf pmf/area converted by cos_y/d^2"},
    {"light-solid-angle", "estimate_light_solid_angle",
     kUsesLights | kUsesLightSelection | kUsesSkyLight,
     "a light by --light-select and a direction uniform in its spherical triangle (Arvo 1995), "
     "area below 3e-4 sr"},
    {"mis", "estimate_mis",
     kUsesLights | kUsesLightSelection | kUsesMisHeuristic | kUsesBsdfSampling | kUsesSkyLight,
     "one light-area and one BSDF-sampled direction, weighted by --mis-heuristic (Veach 1997)"},
    {"ambient-uniform", "estimate_ambient_uniform", kUsesSky,
     "ambient light: sky visibility over uniform directions, albedo x L_sky x (1/pi) int V cos"},
    {"ambient-cosine", "estimate_ambient_cosine", kUsesSky,
     "ambient light: sky visibility over cosine-weighted directions"},
    {"ambient-fibonacci", "estimate_ambient_fibonacci", kUsesSky | kUsesCorrelatedSamples,
     "ambient light: sky visibility over a perturbed spherical Fibonacci spiral of spp points"},
};

const std::vector<OptionVariant> kLightSelectVariants = {
    {"uniform", "LIGHT_SELECT_UNIFORM", "every light with probability 1/lights"},
    {"power", "LIGHT_SELECT_POWER",
     "in proportion to emitted power, CDF inversion by binary search (PBRT 13.3.1), on the 2^-24 "
     "grid"},
    {"alias", "LIGHT_SELECT_ALIAS", "the power distribution by an alias table (Vose 1991), O(1)"},
    {"tree", "LIGHT_SELECT_TREE",
     "a light tree (SAOH-built BVH with orientation cones): power x distance x orientation at the "
     "shading point (Conty Estevez & Kulla 2018; pbrt-v4 BVHLightSampler)"},
};

const std::vector<OptionVariant> kSamplerVariants = {
    {"independent", "SAMPLER_INDEPENDENT",
     "independent uniform numbers, pcg4d of (pixel, sample, dimension, seed)"},
    {"stratified", "SAMPLER_STRATIFIED",
     "jittered strata per dimension pair, permuted per pixel (Kensler 2013)"},
    {"sobol", "SAMPLER_SOBOL", "Owen-scrambled Sobol' pairs, padded by shuffling (Burley 2020)"},
};

// The kernels weigh by the balance heuristic unless MIS_POWER is defined (kernels/api.cl).
const std::vector<OptionVariant> kMisHeuristicVariants = {
    {"balance", nullptr, "w_a = p_a / (p_a + p_b)"},
    {"power", "MIS_POWER", "w_a = p_a^2 / (p_a^2 + p_b^2), beta = 2"},
};

const std::vector<OptionVariant> kMaterialVariants = {
    {"gltf", "MCRT_MATERIALS_GLTF",
     "glTF 2.0 metallic-roughness (Appendix B: GGX, height-correlated Smith, Schlick; "
     "KHR_materials_specular), as the file says"},
    {"lambert", nullptr, "every surface Lambertian, baseColor/pi (the course's model)"},
};

namespace {

template <typename Row>
std::string accepted(const std::vector<Row>& table) {
    std::string names;
    for (const Row& row : table) names += (names.empty() ? "" : ", ") + std::string(row.name);
    return names;
}

}  // namespace

bool light_select_uses_tree(const std::string& name) { return name == "tree"; }

const EstimatorVariant& estimator_variant(const std::string& name) {
    for (const EstimatorVariant& row : kEstimatorVariants)
        if (name == row.name) return row;
    throw InputError("--estimator " + name + ": unknown estimator (one of " +
                     accepted(kEstimatorVariants) + ")");
}

const OptionVariant& option_variant(const std::vector<OptionVariant>& table,
                                    const std::string& name, const char* option) {
    for (const OptionVariant& row : table)
        if (name == row.name) return row;
    throw InputError(std::string(option) + " " + name + ": unknown value (one of " +
                     accepted(table) + ")");
}

std::vector<std::string> variant_names(const std::vector<EstimatorVariant>& table) {
    std::vector<std::string> names;
    for (const EstimatorVariant& row : table) names.push_back(row.name);
    return names;
}

std::vector<std::string> variant_names(const std::vector<OptionVariant>& table) {
    std::vector<std::string> names;
    for (const OptionVariant& row : table) names.push_back(row.name);
    return names;
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

std::string variants_json() {
    nlohmann::json estimators = nlohmann::json::array();
    for (const EstimatorVariant& row : kEstimatorVariants)
        estimators.push_back({{"name", row.name},
                              {"function", row.function},
                              {"uses", uses_names(row.uses)},
                              {"description", row.description}});
    auto options = [](const std::vector<OptionVariant>& table) {
        nlohmann::json rows = nlohmann::json::array();
        for (const OptionVariant& row : table)
            rows.push_back({{"name", row.name},
                            {"macro", row.macro ? nlohmann::json(row.macro) : nlohmann::json()},
                            {"description", row.description}});
        return rows;
    };
    nlohmann::json j = {
        {"estimators", estimators},
        {"light_select", options(kLightSelectVariants)},
        {"samplers", options(kSamplerVariants)},
        {"mis_heuristics", options(kMisHeuristicVariants)},
        {"materials", options(kMaterialVariants)},
        {"user_estimator",
         {{"function", kUserEstimatorFunction}, {"uses", uses_names(kUserEstimatorUses)}}}};
    return j.dump(2) + "\n";
}

std::string variants_text() {
    std::string out = "estimators (--estimator):\n";
    for (const EstimatorVariant& row : kEstimatorVariants) {
        std::string uses;
        for (const std::string& u : uses_names(row.uses)) uses += (uses.empty() ? "" : ",") + u;
        out += "  " + std::string(row.name) + std::string(20 - std::string(row.name).size(), ' ') +
               row.description + " [uses " + uses + "; " + row.function + "]\n";
    }
    auto options = [&out](const char* title, const std::vector<OptionVariant>& table) {
        out += title;
        for (const OptionVariant& row : table)
            out += "  " + std::string(row.name) +
                   std::string(20 - std::string(row.name).size(), ' ') + row.description +
                   (row.macro ? " [-D " + std::string(row.macro) + "]" : "") + "\n";
    };
    options("light selection (--light-select):\n", kLightSelectVariants);
    options("samplers (--sampler):\n", kSamplerVariants);
    options("MIS heuristics (--mis-heuristic):\n", kMisHeuristicVariants);
    options("materials (--materials; the macro only for a scene that is not all Lambertian):\n",
            kMaterialVariants);
    out += "a user's estimator (--estimator-file FILE.cl) defines float3 " +
           std::string(kUserEstimatorFunction) + "(...): docs/ESTIMATORS.md\n";
    return out;
}

}  // namespace mcrt
