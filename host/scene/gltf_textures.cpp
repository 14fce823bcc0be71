// glTF textureInfo as TextureRef: the texture (glTF 2.0 "Textures"), its sampler ("Samplers"),
// the texture coordinate set, and KHR_texture_transform's 2×3 matrix.
#include "scene/gltf_textures.h"

#include <cmath>
#include <limits>

namespace mcrt::gltf {

namespace {

// Texture extensions whose image mcrt does not decode: a client that does not implement one
// reads the texture's own `source`, the fallback ("Textures"; each extension's "Fallback").
const char* const kImageExtensions[] = {"KHR_texture_basisu", "EXT_texture_webp",
                                        "MSFT_texture_dds"};

// The number in `value`; NaN where it is none, so that a finiteness check refuses it.
double number_or_nan(const tinygltf::Value& value) {
    return value.IsNumber() ? value.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
}

// KHR_texture_transform's property `key`: 2 finite numbers, `fallback` when absent.
glm::dvec2 number_pair(const tinygltf::Value& transform, const char* key, glm::dvec2 fallback,
                       const std::string& element, const Diagnostics& diag) {
    if (!transform.Has(key)) return fallback;
    const tinygltf::Value& value = transform.Get(key);
    bool ok = value.IsArray() && value.ArrayLen() == 2;
    glm::dvec2 pair(0.0);
    for (int k = 0; ok && k < 2; ++k) {
        pair[k] = number_or_nan(value.Get(k));
        ok = std::isfinite(pair[k]);
    }
    if (!ok) {
        diag.fail(element,
                  std::string("KHR_texture_transform.") + key + " must be 2 finite numbers");
    }
    return pair;
}

// KHR_texture_transform on a textureInfo: (u', v') = T(offset) R(rotation) S(scale) (u, v, 1)
// with R = [cos sin; −sin cos] (the UVs turn counter-clockwise, the image clockwise), computed in
// double and rounded once; and the texCoord it overrides.
void read_transform(const tinygltf::ExtensionMap& extensions, const std::string& element,
                    const Diagnostics& diag, TextureRef& ref, int& texcoord) {
    const auto found = extensions.find("KHR_texture_transform");
    if (found == extensions.end()) return;
    const tinygltf::Value& transform = found->second;
    if (!transform.IsObject()) diag.fail(element, "KHR_texture_transform must be an object");
    const glm::dvec2 offset = number_pair(transform, "offset", glm::dvec2(0.0), element, diag);
    const glm::dvec2 scale = number_pair(transform, "scale", glm::dvec2(1.0), element, diag);
    double rotation = 0.0;
    if (transform.Has("rotation")) {
        rotation = number_or_nan(transform.Get("rotation"));
        if (!std::isfinite(rotation)) {
            diag.fail(element, "KHR_texture_transform.rotation must be a finite number");
        }
    }
    if (transform.Has("texCoord")) {
        const double set = number_or_nan(transform.Get("texCoord"));
        if (!(set >= 0.0 && set <= 1e9 && set == std::floor(set))) {
            diag.fail(element, "KHR_texture_transform.texCoord must be a non-negative integer");
        }
        texcoord = int(set);
    }
    const double c = std::cos(rotation), s = std::sin(rotation);
    ref.row_u = glm::vec3(glm::dvec3(c * scale.x, s * scale.y, offset.x));
    ref.row_v = glm::vec3(glm::dvec3(-s * scale.x, c * scale.y, offset.y));
    const glm::vec3 rows[2] = {ref.row_u, ref.row_v};
    for (const glm::vec3& row : rows) {
        if (!is_finite(glm::dvec3(row))) {
            diag.fail(element, "KHR_texture_transform overflows single precision");
        }
    }
}

// "Samplers": wrapS and wrapT, REPEAT when absent.
TextureWrap wrap_mode(int value, const char* what, const std::string& element,
                      const Diagnostics& diag) {
    switch (value) {
        case TINYGLTF_TEXTURE_WRAP_REPEAT:
            return TextureWrap::Repeat;
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
            return TextureWrap::ClampToEdge;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
            return TextureWrap::MirroredRepeat;
    }
    diag.fail(element, std::string(what) + " " + std::to_string(value) +
                           " is not a wrap mode (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 "
                           "MIRRORED_REPEAT)");
}

}  // namespace

TextureTable::TextureTable(const tinygltf::Model& model, Diagnostics& diag)
    : model_(model), diag_(diag) {}

// "Texture Data": textureInfo.index names a texture, texCoord its TEXCOORD_n set (0 when absent).
TextureRef TextureTable::read(int index, int texcoord, const tinygltf::ExtensionMap& extensions,
                              bool srgb, const std::string& element) {
    TextureRef ref;
    ref.srgb = srgb;
    if (index == -1) return ref;
    const tinygltf::Texture& texture =
        checked_at(model_.textures, index, "texture", element, diag_);
    const std::string texture_element = element_name("texture", size_t(index));
    const int image = source_image(texture, texture_element);
    if (image == -1) return ref;
    read_sampler(texture.sampler, texture_element, ref);
    read_transform(extensions, element, diag_, ref, texcoord);
    // The kernels read TEXCOORD_0 and TEXCOORD_1 (Scene::texcoords); "Meshes" requires a client
    // to support at least these two.
    if (texcoord != 0 && texcoord != 1) {
        diag_.fail(element, "texCoord " + std::to_string(texcoord) +
                                " is not read: mcrt reads TEXCOORD_0 and TEXCOORD_1");
    }
    ref.texcoord = uint32_t(texcoord);
    ref.image = image_slot(image);
    return ref;
}

TextureRef TextureTable::read_value(const tinygltf::Value& info, bool srgb,
                                    const std::string& element) {
    // check_gltf_types has checked the object: a required integer index and texCoord within int.
    auto integer = [&](const char* name, int fallback) {
        if (!info.Has(name)) return fallback;
        const tinygltf::Value& v = info.Get(name);
        if (!v.IsInt()) diag_.fail(element, std::string(name) + " must be an integer");
        return v.Get<int>();
    };
    tinygltf::ExtensionMap extensions;
    if (info.Has("extensions") && info.Get("extensions").IsObject()) {
        const tinygltf::Value& e = info.Get("extensions");
        for (const std::string& key : e.Keys()) extensions[key] = e.Get(key);
    }
    return read(integer("index", -1), integer("texCoord", 0), extensions, srgb, element);
}

// The glTF image `texture` reads; −1 (with one warning) when it names none.
int TextureTable::source_image(const tinygltf::Texture& texture,
                               const std::string& texture_element) {
    for (const char* extension : kImageExtensions) {
        if (!texture.extensions.count(extension)) continue;
        if (texture.source == -1) {
            diag_.fail(texture_element, std::string("its image comes with ") + extension +
                                            ", which mcrt does not implement, and it has no "
                                            "fallback source (PNG and JPEG are read)");
        }
        diag_.warn_once(extension, texture_element + ": " + extension +
                                       " is not implemented; its fallback source image " +
                                       std::to_string(texture.source) + " is used");
    }
    if (texture.source == -1) {
        diag_.warn_once("texture-source",
                        texture_element + " has no source image; the slot is left empty");
        return -1;
    }
    checked_at(model_.images, texture.source, "source image", texture_element, diag_);
    return texture.source;
}

// "Samplers": no sampler is REPEAT in both directions with the implementation's filters, here
// LINEAR magnification. minFilter is ignored: the images have no mip levels, and a pixel's samples,
// each a texture lookup at a jittered point, average a minified texture over the pixel's
// footprint (the Monte Carlo pixel integral filters it).
void TextureTable::read_sampler(int sampler_index, const std::string& texture_element,
                                TextureRef& ref) {
    if (sampler_index == -1) return;
    const tinygltf::Sampler& sampler =
        checked_at(model_.samplers, sampler_index, "sampler", texture_element, diag_);
    const std::string element = element_name("sampler", size_t(sampler_index));
    ref.wrap_s = wrap_mode(sampler.wrapS, "wrapS", element, diag_);
    ref.wrap_t = wrap_mode(sampler.wrapT, "wrapT", element, diag_);
    if (sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) {
        ref.linear = false;
    } else if (sampler.magFilter != -1 && sampler.magFilter != TINYGLTF_TEXTURE_FILTER_LINEAR) {
        diag_.fail(element, "magFilter " + std::to_string(sampler.magFilter) +
                                " is not a filter (9728 NEAREST, 9729 LINEAR)");
    }
}

int32_t TextureTable::image_slot(int image_index) {
    const auto found = image_slots_.find(image_index);
    if (found != image_slots_.end()) return found->second;
    const int32_t slot = int32_t(sources_.size());
    sources_.push_back(image_index);
    image_slots_.emplace(image_index, slot);
    return slot;
}

}  // namespace mcrt::gltf
