#include "scene/gltf_types.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "common/error.h"

namespace mcrt {

namespace {

using nlohmann::json;

enum class Kind { Integer, Number, String, Boolean, Object, IntegerArray, NumberArray, StringArray };

const char* kind_name(Kind kind) {
    switch (kind) {
        case Kind::Integer: return "an integer";
        case Kind::Number: return "a number";
        case Kind::String: return "a string";
        case Kind::Boolean: return "a boolean";
        case Kind::Object: return "an object";
        case Kind::IntegerArray: return "an array of integers";
        case Kind::NumberArray: return "an array of numbers";
        case Kind::StringArray: return "an array of strings";
    }
    return "?";
}

bool is_integer(const json& v) {
    if (v.is_number_integer()) return true;
    if (!v.is_number_float()) return false;
    const double d = v.get<double>();
    return std::isfinite(d) && d == std::floor(d);
}

bool has_kind(const json& v, Kind kind) {
    auto all = [&](auto test) {
        if (!v.is_array()) return false;
        for (const json& item : v)
            if (!test(item)) return false;
        return true;
    };
    switch (kind) {
        case Kind::Integer: return is_integer(v);
        case Kind::Number: return v.is_number();
        case Kind::String: return v.is_string();
        case Kind::Boolean: return v.is_boolean();
        case Kind::Object: return v.is_object();
        case Kind::IntegerArray: return all(is_integer);
        case Kind::NumberArray: return all([](const json& x) { return x.is_number(); });
        case Kind::StringArray: return all([](const json& x) { return x.is_string(); });
    }
    return false;
}

const char* found_name(const json& v) {
    if (v.is_array()) return "an array";
    if (v.is_object()) return "an object";
    if (v.is_string()) return "a string";
    if (v.is_boolean()) return "a boolean";
    if (v.is_null()) return "null";
    return "a number";
}

struct Property {
    const char* key;
    Kind kind;
};

class Checker {
  public:
    explicit Checker(const std::string& name) : name_(name) {}

    void properties(const json& object, const std::string& where,
                    std::initializer_list<Property> expected) const {
        if (!object.is_object()) fail(where, "an object", object);
        for (const Property& p : expected) {
            const auto found = object.find(p.key);
            if (found != object.end() && !has_kind(*found, p.kind))
                fail(where + "." + p.key, kind_name(p.kind), *found);
        }
    }

    // Each element of the array `root[key]`, if present, an object checked by `each`.
    template <typename Each>
    void array_of_objects(const json& root, const char* key, const std::string& where,
                          Each each) const {
        const auto found = root.find(key);
        if (found == root.end()) return;
        const std::string path = where.empty() ? key : where + "." + key;
        if (!found->is_array()) fail(path, "an array", *found);
        for (size_t i = 0; i < found->size(); ++i) {
            const json& item = (*found)[i];
            const std::string item_path = path + "[" + std::to_string(i) + "]";
            if (!item.is_object()) fail(item_path, "an object", item);
            each(item, item_path);
        }
    }

    // "Texture Data": a textureInfo, whose index tinygltf leaves at −1 (no texture) when it is
    // missing, and its KHR_texture_transform.
    void texture_info(const json& object, const std::string& where) const {
        properties(object, where, {{"index", Kind::Integer}, {"texCoord", Kind::Integer},
                                   {"scale", Kind::Number}, {"strength", Kind::Number},
                                   {"extensions", Kind::Object}});
        if (!object.contains("index")) {
            throw InputError(name_ + ": " + where + ".index: required, an integer");
        }
        if (const auto ext = object.find("extensions"); ext != object.end()) {
            if (const auto t = ext->find("KHR_texture_transform"); t != ext->end())
                properties(*t, where + ".extensions.KHR_texture_transform",
                           {{"offset", Kind::NumberArray}, {"rotation", Kind::Number},
                            {"scale", Kind::NumberArray}, {"texCoord", Kind::Integer}});
        }
    }

    [[noreturn]] void fail(const std::string& where, const char* expected, const json& v) const {
        throw InputError(name_ + ": " + where + ": expected " + expected + ", found " +
                         found_name(v));
    }

  private:
    const std::string& name_;
};

}  // namespace

void check_gltf_property_types(const std::string& name, const unsigned char* data, size_t size) {
    const json root = json::parse(data, data + size, nullptr, false);
    if (root.is_discarded() || !root.is_object()) return;  // tinygltf reports it
    const Checker c(name);
    c.properties(root, "glTF", {{"scene", Kind::Integer}, {"asset", Kind::Object},
                                {"extensionsRequired", Kind::StringArray},
                                {"extensionsUsed", Kind::StringArray}});
    if (const auto asset = root.find("asset"); asset != root.end())
        c.properties(*asset, "asset", {{"version", Kind::String}, {"minVersion", Kind::String}});
    c.array_of_objects(root, "scenes", "", [&](const json& s, const std::string& at) {
        c.properties(s, at, {{"nodes", Kind::IntegerArray}});
    });
    c.array_of_objects(root, "nodes", "", [&](const json& n, const std::string& at) {
        c.properties(n, at, {{"mesh", Kind::Integer}, {"camera", Kind::Integer},
                             {"skin", Kind::Integer}, {"children", Kind::IntegerArray},
                             {"matrix", Kind::NumberArray}, {"translation", Kind::NumberArray},
                             {"rotation", Kind::NumberArray}, {"scale", Kind::NumberArray},
                             {"weights", Kind::NumberArray}, {"extensions", Kind::Object}});
    });
    c.array_of_objects(root, "meshes", "", [&](const json& m, const std::string& at) {
        c.array_of_objects(m, "primitives", at, [&](const json& p, const std::string& pat) {
            c.properties(p, pat, {{"attributes", Kind::Object}, {"indices", Kind::Integer},
                                  {"material", Kind::Integer}, {"mode", Kind::Integer}});
            if (const auto a = p.find("attributes"); a != p.end())
                for (const auto& [key, value] : a->items())
                    if (!is_integer(value)) c.fail(pat + ".attributes." + key, "an integer", value);
        });
    });
    c.array_of_objects(root, "materials", "", [&](const json& m, const std::string& at) {
        c.properties(m, at, {{"pbrMetallicRoughness", Kind::Object},
                             {"emissiveFactor", Kind::NumberArray}, {"doubleSided", Kind::Boolean},
                             {"alphaMode", Kind::String}, {"alphaCutoff", Kind::Number},
                             {"normalTexture", Kind::Object}, {"occlusionTexture", Kind::Object},
                             {"emissiveTexture", Kind::Object}, {"extensions", Kind::Object}});
        for (const char* slot : {"normalTexture", "occlusionTexture", "emissiveTexture"})
            if (const auto info = m.find(slot); info != m.end())
                c.texture_info(*info, at + "." + slot);
        if (const auto pbr = m.find("pbrMetallicRoughness"); pbr != m.end()) {
            c.properties(*pbr, at + ".pbrMetallicRoughness",
                         {{"baseColorFactor", Kind::NumberArray}, {"metallicFactor", Kind::Number},
                          {"roughnessFactor", Kind::Number}, {"baseColorTexture", Kind::Object},
                          {"metallicRoughnessTexture", Kind::Object}});
            for (const char* slot : {"baseColorTexture", "metallicRoughnessTexture"})
                if (const auto info = pbr->find(slot); info != pbr->end())
                    c.texture_info(*info, at + ".pbrMetallicRoughness." + slot);
        }
        if (const auto ext = m.find("extensions"); ext != m.end()) {
            const auto strength = ext->find("KHR_materials_emissive_strength");
            if (strength != ext->end())
                c.properties(*strength, at + ".extensions.KHR_materials_emissive_strength",
                             {{"emissiveStrength", Kind::Number}});
        }
    });
    c.array_of_objects(root, "textures", "", [&](const json& t, const std::string& at) {
        c.properties(t, at, {{"sampler", Kind::Integer}, {"source", Kind::Integer},
                             {"extensions", Kind::Object}});
    });
    c.array_of_objects(root, "samplers", "", [&](const json& t, const std::string& at) {
        c.properties(t, at, {{"magFilter", Kind::Integer}, {"minFilter", Kind::Integer},
                             {"wrapS", Kind::Integer}, {"wrapT", Kind::Integer}});
    });
    c.array_of_objects(root, "images", "", [&](const json& i, const std::string& at) {
        c.properties(i, at, {{"uri", Kind::String}, {"mimeType", Kind::String},
                             {"bufferView", Kind::Integer}});
    });
    c.array_of_objects(root, "accessors", "", [&](const json& a, const std::string& at) {
        c.properties(a, at, {{"bufferView", Kind::Integer}, {"byteOffset", Kind::Integer},
                             {"componentType", Kind::Integer}, {"count", Kind::Integer},
                             {"type", Kind::String}, {"normalized", Kind::Boolean},
                             {"sparse", Kind::Object}});
    });
    c.array_of_objects(root, "bufferViews", "", [&](const json& v, const std::string& at) {
        c.properties(v, at, {{"buffer", Kind::Integer}, {"byteOffset", Kind::Integer},
                             {"byteLength", Kind::Integer}, {"byteStride", Kind::Integer}});
    });
    c.array_of_objects(root, "buffers", "", [&](const json& b, const std::string& at) {
        c.properties(b, at, {{"byteLength", Kind::Integer}, {"uri", Kind::String}});
    });
    c.array_of_objects(root, "cameras", "", [&](const json& cam, const std::string& at) {
        c.properties(cam, at, {{"type", Kind::String}, {"perspective", Kind::Object}});
        if (const auto p = cam.find("perspective"); p != cam.end())
            c.properties(*p, at + ".perspective",
                         {{"yfov", Kind::Number}, {"znear", Kind::Number}, {"zfar", Kind::Number},
                          {"aspectRatio", Kind::Number}});
    });
}

}  // namespace mcrt
