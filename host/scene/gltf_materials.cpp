// glTF materials as mcrt's Material: the metallic-roughness factors (glTF 2.0 Appendix B),
// emission with KHR_materials_emissive_strength, KHR_materials_specular, KHR_materials_ior,
// KHR_materials_transmission and KHR_materials_volume, the alpha mode and the texture slots
// (gltf_textures.cpp); what is ignored warned.
#include "scene/gltf_materials.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "common/value_limits.h"

namespace mcrt::gltf {

namespace {

// `values` are exactly `size` finite non-negative numbers.
bool finite_non_negative(const std::vector<double>& values, size_t size) {
    return values.size() == size && all_finite(values) &&
           *std::min_element(values.begin(), values.end()) >= 0.0;
}

// A factor the specification bounds to [0, 1]: NaN and infinities fail, others are clamped
// with one warning.
float unit_factor(double value, const char* what, const std::string& element, Diagnostics& diag) {
    if (!std::isfinite(value)) diag.fail(element, std::string(what) + " must be a finite number");
    if (value < 0.0 || value > 1.0) {
        diag.warn_once(
            std::string("factor-") + what,
            element + ": " + what + " " + format_number(value) + " is outside [0, 1]; clamped");
        value = std::clamp(value, 0.0, 1.0);
    }
    return float(value);
}

// glTF 2.0 Appendix B's parameters: metallicFactor, roughnessFactor (default 1 each), and
// KHR_materials_specular's specularFactor (default 1) and specularColorFactor (default 1, 1, 1;
// F0 = min(f0(ior) × it, 1) is clamped where the BRDF is built, host/render/gpu_scene.cpp).
void read_microfacet_factors(const tinygltf::Material& source, const std::string& element,
                             Diagnostics& diag, Material& material) {
    const auto& pbr = source.pbrMetallicRoughness;
    material.metallic = unit_factor(pbr.metallicFactor, "metallicFactor", element, diag);
    material.roughness = unit_factor(pbr.roughnessFactor, "roughnessFactor", element, diag);
    material.specular = 1.0f;
    material.specular_color = glm::vec3(1.0f);
    const auto extension = source.extensions.find("KHR_materials_specular");
    if (extension == source.extensions.end() || !extension->second.IsObject()) return;
    const tinygltf::Value& ext = extension->second;
    if (ext.Has("specularFactor")) {
        const tinygltf::Value& v = ext.Get("specularFactor");
        material.specular = unit_factor(
            v.IsNumber() ? v.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN(),
            "KHR_materials_specular.specularFactor", element, diag);
    }
    if (ext.Has("specularColorFactor")) {
        const tinygltf::Value& v = ext.Get("specularColorFactor");
        bool ok = v.IsArray() && v.ArrayLen() == 3;
        glm::dvec3 c(0.0);
        for (int k = 0; ok && k < 3; ++k) {
            ok = v.Get(k).IsNumber();
            if (ok) c[k] = v.Get(k).GetNumberAsDouble();
            ok = ok && std::isfinite(c[k]) && c[k] >= 0.0 && c[k] <= 1e30;
        }
        if (!ok) {
            diag.fail(element,
                      "KHR_materials_specular.specularColorFactor must be 3 finite "
                      "non-negative numbers");
        }
        material.specular_color = glm::vec3(c);
    }
}

// A number of an extension object, or NaN where it is there but not a number (refused by the
// caller's finiteness check); `fallback` where it is absent.
double extension_number(const tinygltf::Value& ext, const char* name, double fallback) {
    if (!ext.Has(name)) return fallback;
    const tinygltf::Value& v = ext.Get(name);
    return v.IsNumber() ? v.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
}

// The largest index of refraction read as given; beyond it (F0 > 0.9996) the value is clamped,
// so that ior² stays far from float's range in the kernels.
constexpr double kMaxIor = 1e4;

// KHR_materials_ior: `ior` ≥ 1, or exactly 0 (the extension's specular-glossiness mode, where
// the Fresnel term is 1); default 1.5. Not a finite number: refused. Below 1 (but not 0): the
// default with one warning. Above kMaxIor: clamped with one warning.
void read_ior(const tinygltf::Material& source, const std::string& element, Diagnostics& diag,
              Material& material) {
    material.ior = 1.5f;
    const auto extension = source.extensions.find("KHR_materials_ior");
    if (extension == source.extensions.end() || !extension->second.IsObject()) return;
    double ior = extension_number(extension->second, "ior", 1.5);
    if (!std::isfinite(ior)) diag.fail(element, "KHR_materials_ior.ior must be a finite number");
    if (ior != 0.0 && ior < 1.0) {
        diag.warn_once("ior-range", element + ": KHR_materials_ior.ior " + format_number(ior) +
                                        " is neither 0 nor at least 1; the default 1.5 is used");
        ior = 1.5;
    } else if (ior > kMaxIor) {
        diag.warn_once("ior-large", element + ": KHR_materials_ior.ior " + format_number(ior) +
                                        " is above " + format_number(kMaxIor) + "; clamped");
        ior = kMaxIor;
    }
    material.ior = float(ior);
}

// The extension object `name` of a material, or null where it is absent (or not an object).
const tinygltf::Value* extension_object(const tinygltf::Material& source, const char* name) {
    const auto extension = source.extensions.find(name);
    if (extension == source.extensions.end() || !extension->second.IsObject()) return nullptr;
    return &extension->second;
}

// KHR_materials_transmission: transmissionFactor in [0, 1] (default 0), times the R channel of
// transmissionTexture (linear) where there is one.
// KHR_materials_volume (only with transmission): thicknessFactor ≥ 0 (default 0, thin-walled);
// > 0 makes the surface bound a volume (thicknessTexture only matters to rasterizers that
// fake refraction, and is not read); attenuationColor in [0, 1]³ (default white), clamped with
// one warning; attenuationDistance > 0 (default ∞): 0 or negative is read as ∞, with one warning.
void read_transmission(const tinygltf::Material& source, const std::string& element,
                       TextureTable& textures, Diagnostics& diag, Material& material) {
    const tinygltf::Value* ext = extension_object(source, "KHR_materials_transmission");
    if (!ext) return;
    material.transmission =
        unit_factor(extension_number(*ext, "transmissionFactor", 0.0),
                    "KHR_materials_transmission.transmissionFactor", element, diag);
    if (ext->Has("transmissionTexture") && material.transmission > 0.0f) {
        material.transmission_texture =
            textures.read_value(ext->Get("transmissionTexture"), false,
                                element + " KHR_materials_transmission.transmissionTexture");
    }
    const tinygltf::Value* volume = extension_object(source, "KHR_materials_volume");
    if (!volume || material.transmission == 0.0f) return;
    const double thickness = extension_number(*volume, "thicknessFactor", 0.0);
    if (!std::isfinite(thickness) || thickness < 0.0) {
        diag.fail(element, "KHR_materials_volume.thicknessFactor must be a finite number >= 0");
    }
    material.volume = thickness > 0.0;
    double distance =
        extension_number(*volume, "attenuationDistance", std::numeric_limits<double>::infinity());
    if (std::isnan(distance)) {
        diag.fail(element, "KHR_materials_volume.attenuationDistance must be a number > 0");
    }
    if (!(distance > 0.0)) {
        diag.warn_once("attenuation-distance",
                       element + ": KHR_materials_volume.attenuationDistance " +
                           format_number(distance) + " is not above 0; no attenuation");
        distance = std::numeric_limits<double>::infinity();
    }
    material.attenuation_distance = float(distance);  // beyond float's range: ∞, no loss
    if (volume->Has("attenuationColor")) {
        const tinygltf::Value& v = volume->Get("attenuationColor");
        if (!v.IsArray() || v.ArrayLen() != 3) {
            diag.fail(element, "KHR_materials_volume.attenuationColor must be 3 numbers");
        }
        for (int k = 0; k < 3; ++k) {
            const tinygltf::Value& c = v.Get(k);
            material.attenuation_color[k] = unit_factor(
                c.IsNumber() ? c.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN(),
                "KHR_materials_volume.attenuationColor", element, diag);
        }
    }
}

// KHR_materials_emissive_strength: a non-negative multiplier of emissiveFactor, 1 when absent.
double emissive_strength(const tinygltf::Material& material, const std::string& element,
                         const Diagnostics& diag) {
    const auto extension = material.extensions.find("KHR_materials_emissive_strength");
    if (extension == material.extensions.end()) return 1.0;
    if (!extension->second.IsObject() || !extension->second.Has("emissiveStrength")) return 1.0;
    const tinygltf::Value& value = extension->second.Get("emissiveStrength");
    const double strength =
        value.IsNumber() ? value.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
    if (!(strength >= 0.0) || !std::isfinite(strength)) {
        diag.fail(element,
                  "KHR_materials_emissive_strength.emissiveStrength must be a finite "
                  "non-negative number");
    }
    return strength;
}

// "Alpha Coverage": alphaMode OPAQUE (default), MASK or BLEND; alphaCutoff (default 0.5) a
// finite number >= 0 (the schema's minimum), kept whatever the mode.
void read_alpha(const tinygltf::Material& source, const std::string& element, Diagnostics& diag,
                Material& material) {
    material.alpha = unit_factor(source.pbrMetallicRoughness.baseColorFactor[3],
                                 "baseColorFactor alpha", element, diag);
    if (source.alphaMode == "OPAQUE") {
        material.alpha_mode = AlphaMode::Opaque;
    } else if (source.alphaMode == "MASK") {
        material.alpha_mode = AlphaMode::Mask;
    } else if (source.alphaMode == "BLEND") {
        material.alpha_mode = AlphaMode::Blend;
    } else {
        diag.fail(element, "alphaMode \"" + source.alphaMode + "\" is not OPAQUE, MASK or BLEND");
    }
    if (!std::isfinite(source.alphaCutoff) || source.alphaCutoff < 0.0) {
        diag.fail(element, "alphaCutoff must be a finite number >= 0");
    }
    material.alpha_cutoff = float(source.alphaCutoff);
}

// "Metallic-Roughness Material" and "Additional Textures": each slot multiplies its factor.
// baseColor and emissive textures hold sRGB-encoded colour, metallicRoughness (B metallic, G
// roughness) and normal textures linear values; normalTexture.scale scales the normal's x and y.
void read_texture_slots(const tinygltf::Material& source, const std::string& element,
                        TextureTable& textures, const Diagnostics& diag, Material& material) {
    const auto& pbr = source.pbrMetallicRoughness;
    material.base_color_texture =
        textures.read(pbr.baseColorTexture, true, element + " baseColorTexture");
    material.metallic_roughness_texture =
        textures.read(pbr.metallicRoughnessTexture, false, element + " metallicRoughnessTexture");
    material.normal_texture =
        textures.read(source.normalTexture, false, element + " normalTexture");
    material.emissive_texture =
        textures.read(source.emissiveTexture, true, element + " emissiveTexture");
    if (material.normal_texture.used()) {
        if (!std::isfinite(source.normalTexture.scale)) {
            diag.fail(element, "normalTexture.scale must be a finite number");
        }
        material.normal_scale = float(source.normalTexture.scale);
    }
}

// The texture slots a primitive's texture coordinates feed, named as in glTF.
struct TextureSlot {
    const char* name;
    TextureRef Material::*ref;
};
const TextureSlot kTextureSlots[] = {
    {"baseColorTexture", &Material::base_color_texture},
    {"metallicRoughnessTexture", &Material::metallic_roughness_texture},
    {"normalTexture", &Material::normal_texture},
    {"emissiveTexture", &Material::emissive_texture},
    {"KHR_materials_transmission.transmissionTexture", &Material::transmission_texture}};

// What of a material mcrt does not render, once per kind.
void warn_unsupported_parts(const tinygltf::Material& material, Diagnostics& diag) {
    if (material.occlusionTexture.index != -1) {
        // A path tracer's light transport computes the occlusion such a map approximates.
        diag.warn_once("occlusion",
                       "occlusionTexture is not used: the light transport computes occlusion");
    }
}

}  // namespace

MaterialTable::MaterialTable(const tinygltf::Model& model, Diagnostics& diag,
                             TextureTable& textures, std::vector<Material>& materials)
    : model_(model), diag_(diag), textures_(textures), materials_(materials) {}

uint32_t MaterialTable::slot(int material_index, const std::string& referrer) {
    const auto found = slots_.find(material_index);
    if (found != slots_.end()) return found->second;

    Material material;
    if (material_index == -1) {
        // "Materials": the default material is white, not emissive, single-sided, with the
        // metallic-roughness defaults (metallic 1, roughness 1) and the specular layer of
        // KHR_materials_specular's defaults.
        material.name = "default";
        material.metallic = 1.0f;
        material.roughness = 1.0f;
        material.specular = 1.0f;
    } else {
        material = convert(material_index, referrer);
    }
    const uint32_t index = static_cast<uint32_t>(materials_.size());
    materials_.push_back(material);
    slots_.emplace(material_index, index);
    return index;
}

uint32_t MaterialTable::slot_for_texcoords(uint32_t slot, uint32_t texcoord_sets,
                                           std::string& left_out) {
    left_out.clear();
    uint32_t missing = 0;
    const Material& material = materials_[slot];
    for (size_t k = 0; k < std::size(kTextureSlots); ++k) {
        const TextureRef& ref = material.*kTextureSlots[k].ref;
        if (!ref.used() || (texcoord_sets >> ref.texcoord & 1u)) continue;
        missing |= 1u << k;
        left_out += std::string(left_out.empty() ? "" : ", ") + kTextureSlots[k].name +
                    " (TEXCOORD_" + std::to_string(ref.texcoord) + ")";
    }
    if (missing == 0) return slot;
    const auto found = copies_.find({slot, missing});
    if (found != copies_.end()) return found->second;
    Material copy = material;
    for (size_t k = 0; k < std::size(kTextureSlots); ++k) {
        if (missing >> k & 1u) copy.*kTextureSlots[k].ref = TextureRef{};
    }
    const uint32_t index = static_cast<uint32_t>(materials_.size());
    materials_.push_back(copy);
    copies_.emplace(std::make_pair(slot, missing), index);
    return index;
}

// DESIGN.md "Radiometric contract": albedo = baseColorFactor.rgb,
// Le = emissiveFactor × KHR_materials_emissive_strength.emissiveStrength.
Material MaterialTable::convert(int material_index, const std::string& referrer) {
    const tinygltf::Material& source =
        checked_at(model_.materials, material_index, "material", referrer, diag_);
    const std::string element = element_name("material", static_cast<size_t>(material_index));
    warn_unsupported_parts(source, diag_);

    const std::vector<double>& base = source.pbrMetallicRoughness.baseColorFactor;
    if (!finite_non_negative(base, 4)) {
        diag_.fail(element, "baseColorFactor must be 4 finite non-negative numbers");
    }
    const std::vector<double>& emissive = source.emissiveFactor;
    if (!emissive.empty() && !finite_non_negative(emissive, 3)) {
        diag_.fail(element, "emissiveFactor must be 3 finite non-negative numbers");
    }

    Material material;
    material.name = source.name.empty() ? element : source.name;
    glm::dvec3 albedo(base[0], base[1], base[2]);
    if (max_component(albedo) > 1.0) {
        // An albedo above 1 reflects more than arrives: energy from nothing.
        diag_.warn_once("albedo", element + ": baseColorFactor " +
                                      format_number(max_component(albedo)) +
                                      " is above 1; factors are clamped to [0, 1]");
        albedo = glm::min(albedo, glm::dvec3(1.0));
    }
    material.albedo = glm::vec3(albedo);
    if (!emissive.empty()) {
        const glm::dvec3 Le = glm::dvec3(emissive[0], emissive[1], emissive[2]) *
                              emissive_strength(source, element, diag_);
        material.emission = glm::vec3(Le);
        if (!is_finite(glm::dvec3(material.emission))) {
            diag_.fail(element, "emission overflows single precision");
        }
        if (max_component(Le) > kMaxRadiance) {
            diag_.fail(element, "emission " + format_number(max_component(Le)) + " exceeds " +
                                    format_number(kMaxRadiance) +
                                    ", beyond which an estimate may overflow single precision");
        }
    }
    material.double_sided = source.doubleSided;
    read_microfacet_factors(source, element, diag_, material);
    read_ior(source, element, diag_, material);
    read_transmission(source, element, textures_, diag_, material);
    read_alpha(source, element, diag_, material);
    read_texture_slots(source, element, textures_, diag_, material);
    return material;
}

}  // namespace mcrt::gltf
