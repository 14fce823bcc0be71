#include "scene/gltf_types.h"

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>

#include "common/error.h"

namespace mcrt {

namespace {

using nlohmann::json;

// What a property holds. The integer kinds follow what tinygltf 2.7 converts them to, since it
// converts without a check: Int32 and Index properties go into `int` with a cast (4294967297 reads
// as 1, another valid index), Unsigned ones into size_t (a negative value or 4.0 reads as absent),
// and any integer inside an extension becomes a tinygltf::Value of `int` (ExtensionNumber). Every
// integer kind takes JSON integers alone: tinygltf drops 1.0 or 1e0 as if the property were absent.
enum class Kind {
    Int32,            // an enumeration tinygltf keeps in an int: mode, wrapS, magFilter, ...
    Index,            // a glTF id (or an int count or offset): 0 to INT_MAX
    Unsigned,         // a size_t of tinygltf: byteOffset, byteLength, byteStride, count
    Number,           // a double of tinygltf
    ExtensionNumber,  // a number of an extension: no integer beyond int range (other values,
                      // strings included, are left to the code that reads the extension)
    String,
    Boolean,
    Object,
    IndexArray,
    NumberArray,
    ExtensionNumberArray,
    StringArray
};

constexpr int64_t kIntMin = std::numeric_limits<int>::min();
constexpr int64_t kIntMax = std::numeric_limits<int>::max();

// A JSON integer (no fraction, no exponent) within [low, high]; nlohmann keeps integers up to
// 2^64 − 1 as integers and larger ones as doubles.
bool integer_within(const json& v, int64_t low, int64_t high) {
    if (v.is_number_unsigned()) return v.get<uint64_t>() <= uint64_t(high);
    if (v.is_number_integer()) return v.get<int64_t>() >= low && v.get<int64_t>() <= high;
    return false;
}

bool has_kind(const json& v, Kind kind) {
    auto all = [&](Kind item_kind) {
        if (!v.is_array()) return false;
        for (const json& item : v)
            if (!has_kind(item, item_kind)) return false;
        return true;
    };
    switch (kind) {
        case Kind::Int32:
            return integer_within(v, kIntMin, kIntMax);
        case Kind::Index:
            return integer_within(v, 0, kIntMax);
        case Kind::Unsigned:
            return v.is_number_unsigned();
        case Kind::Number:
            return v.is_number();
        case Kind::ExtensionNumber:
            return !v.is_number_integer() || integer_within(v, kIntMin, kIntMax);
        case Kind::String:
            return v.is_string();
        case Kind::Boolean:
            return v.is_boolean();
        case Kind::Object:
            return v.is_object();
        case Kind::IndexArray:
            return all(Kind::Index);
        case Kind::NumberArray:
            return all(Kind::Number);
        case Kind::ExtensionNumberArray:
            return !v.is_array() || all(Kind::ExtensionNumber);
        case Kind::StringArray:
            return all(Kind::String);
    }
    return false;
}

const char* kind_name(Kind kind) {
    switch (kind) {
        case Kind::Int32:
            return "an integer from -2147483648 to 2147483647";
        case Kind::Index:
            return "an integer from 0 to 2147483647";
        case Kind::Unsigned:
            return "a non-negative integer";
        case Kind::Number:
            return "a number";
        case Kind::ExtensionNumber:
            return "a number, as an integer from -2147483648 to 2147483647 (tinygltf keeps an "
                   "extension's integers in 32 bits: write a larger one with a fraction, as "
                   "4294967296.0)";
        case Kind::String:
            return "a string";
        case Kind::Boolean:
            return "a boolean";
        case Kind::Object:
            return "an object";
        case Kind::IndexArray:
            return "an array of integers from 0 to 2147483647";
        case Kind::NumberArray:
            return "an array of numbers";
        case Kind::ExtensionNumberArray:
            return "an array of numbers";  // named per element
        case Kind::StringArray:
            return "an array of strings";
    }
    return "?";
}

// The kind of each element of an array kind; Kind::Object (none) for the others.
Kind item_kind(Kind kind) {
    switch (kind) {
        case Kind::IndexArray:
            return Kind::Index;
        case Kind::NumberArray:
            return Kind::Number;
        case Kind::ExtensionNumberArray:
            return Kind::ExtensionNumber;
        case Kind::StringArray:
            return Kind::String;
        default:
            return Kind::Object;
    }
}

// What was found: a number as written (4294967297, 1.0, -1), else its JSON type.
std::string found_name(const json& v) {
    if (v.is_number()) return v.dump();
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
            if (found != object.end()) value(*found, where + "." + p.key, p.kind);
        }
    }

    // `v` of `kind`; an array's first wrong element is named by its position.
    void value(const json& v, const std::string& where, Kind kind) const {
        if (has_kind(v, kind)) return;
        const Kind item = item_kind(kind);
        if (item == Kind::Object || !v.is_array()) fail(where, kind_name(kind), v);
        for (size_t i = 0; i < v.size(); ++i)
            value(v[i], where + "[" + std::to_string(i) + "]", item);
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

    // The object `root[key]`, if present, checked by `each`.
    template <typename Each>
    void object(const json& root, const char* key, const std::string& where, Each each) const {
        const auto found = root.find(key);
        if (found == root.end()) return;
        const std::string path = where + "." + key;
        if (!found->is_object()) fail(path, "an object", *found);
        each(*found, path);
    }

    // Every value of the object `v` (attributes, morph targets) an index.
    void index_values(const json& v, const std::string& where) const {
        if (!v.is_object()) fail(where, "an object", v);
        for (const auto& [key, item] : v.items()) value(item, where + "." + key, Kind::Index);
    }

    // "Texture Data": a textureInfo, whose index tinygltf leaves at −1 (no texture) when it is
    // missing, and its KHR_texture_transform.
    void texture_info(const json& object, const std::string& where) const {
        properties(object, where,
                   {{"index", Kind::Index},
                    {"texCoord", Kind::Index},
                    {"scale", Kind::Number},
                    {"strength", Kind::Number},
                    {"extensions", Kind::Object}});
        if (!object.contains("index")) {
            throw InputError(name_ + ": " + where + ".index: required, an integer");
        }
        if (const auto ext = object.find("extensions"); ext != object.end()) {
            if (const auto t = ext->find("KHR_texture_transform"); t != ext->end())
                properties(*t, where + ".extensions.KHR_texture_transform",
                           {{"offset", Kind::ExtensionNumberArray},
                            {"rotation", Kind::ExtensionNumber},
                            {"scale", Kind::ExtensionNumberArray},
                            {"texCoord", Kind::Index}});
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
    c.properties(root, "glTF",
                 {{"scene", Kind::Index},
                  {"asset", Kind::Object},
                  {"extensionsRequired", Kind::StringArray},
                  {"extensionsUsed", Kind::StringArray}});
    if (const auto asset = root.find("asset"); asset != root.end())
        c.properties(*asset, "asset", {{"version", Kind::String}, {"minVersion", Kind::String}});
    c.array_of_objects(root, "scenes", "", [&](const json& s, const std::string& at) {
        c.properties(s, at, {{"nodes", Kind::IndexArray}});
    });
    c.array_of_objects(root, "nodes", "", [&](const json& n, const std::string& at) {
        c.properties(n, at,
                     {{"mesh", Kind::Index},
                      {"camera", Kind::Index},
                      {"skin", Kind::Index},
                      {"children", Kind::IndexArray},
                      {"matrix", Kind::NumberArray},
                      {"translation", Kind::NumberArray},
                      {"rotation", Kind::NumberArray},
                      {"scale", Kind::NumberArray},
                      {"weights", Kind::NumberArray},
                      {"extensions", Kind::Object}});
    });
    c.array_of_objects(root, "meshes", "", [&](const json& m, const std::string& at) {
        c.array_of_objects(m, "primitives", at, [&](const json& p, const std::string& pat) {
            c.properties(p, pat,
                         {{"attributes", Kind::Object},
                          {"indices", Kind::Index},
                          {"material", Kind::Index},
                          {"mode", Kind::Int32}});
            if (const auto a = p.find("attributes"); a != p.end())
                c.index_values(*a, pat + ".attributes");
            c.array_of_objects(p, "targets", pat, [&](const json& t, const std::string& tat) {
                c.index_values(t, tat);
            });
        });
    });
    c.array_of_objects(root, "materials", "", [&](const json& m, const std::string& at) {
        c.properties(m, at,
                     {{"pbrMetallicRoughness", Kind::Object},
                      {"emissiveFactor", Kind::NumberArray},
                      {"doubleSided", Kind::Boolean},
                      {"alphaMode", Kind::String},
                      {"alphaCutoff", Kind::Number},
                      {"normalTexture", Kind::Object},
                      {"occlusionTexture", Kind::Object},
                      {"emissiveTexture", Kind::Object},
                      {"extensions", Kind::Object}});
        for (const char* slot : {"normalTexture", "occlusionTexture", "emissiveTexture"})
            if (const auto info = m.find(slot); info != m.end())
                c.texture_info(*info, at + "." + slot);
        if (const auto pbr = m.find("pbrMetallicRoughness"); pbr != m.end()) {
            c.properties(*pbr, at + ".pbrMetallicRoughness",
                         {{"baseColorFactor", Kind::NumberArray},
                          {"metallicFactor", Kind::Number},
                          {"roughnessFactor", Kind::Number},
                          {"baseColorTexture", Kind::Object},
                          {"metallicRoughnessTexture", Kind::Object}});
            for (const char* slot : {"baseColorTexture", "metallicRoughnessTexture"})
                if (const auto info = pbr->find(slot); info != pbr->end())
                    c.texture_info(*info, at + ".pbrMetallicRoughness." + slot);
        }
        if (const auto ext = m.find("extensions"); ext != m.end()) {
            const std::string ext_at = at + ".extensions";
            c.object(*ext, "KHR_materials_emissive_strength", ext_at,
                     [&](const json& e, const std::string& eat) {
                         c.properties(e, eat, {{"emissiveStrength", Kind::ExtensionNumber}});
                     });
            c.object(*ext, "KHR_materials_transmission", ext_at,
                     [&](const json& e, const std::string& eat) {
                         c.properties(e, eat,
                                      {{"transmissionFactor", Kind::ExtensionNumber},
                                       {"transmissionTexture", Kind::Object}});
                         if (const auto info = e.find("transmissionTexture"); info != e.end())
                             c.texture_info(*info, eat + ".transmissionTexture");
                     });
            c.object(*ext, "KHR_materials_specular", ext_at,
                     [&](const json& e, const std::string& eat) {
                         c.properties(e, eat,
                                      {{"specularFactor", Kind::ExtensionNumber},
                                       {"specularColorFactor", Kind::ExtensionNumberArray}});
                     });
        }
    });
    c.array_of_objects(root, "textures", "", [&](const json& t, const std::string& at) {
        c.properties(
            t, at,
            {{"sampler", Kind::Index}, {"source", Kind::Index}, {"extensions", Kind::Object}});
    });
    c.array_of_objects(root, "samplers", "", [&](const json& t, const std::string& at) {
        c.properties(t, at,
                     {{"magFilter", Kind::Int32},
                      {"minFilter", Kind::Int32},
                      {"wrapS", Kind::Int32},
                      {"wrapT", Kind::Int32}});
    });
    c.array_of_objects(root, "images", "", [&](const json& i, const std::string& at) {
        c.properties(
            i, at,
            {{"uri", Kind::String}, {"mimeType", Kind::String}, {"bufferView", Kind::Index}});
    });
    c.array_of_objects(root, "accessors", "", [&](const json& a, const std::string& at) {
        c.properties(a, at,
                     {{"bufferView", Kind::Index},
                      {"byteOffset", Kind::Unsigned},
                      {"componentType", Kind::Unsigned},
                      {"count", Kind::Unsigned},
                      {"type", Kind::String},
                      {"normalized", Kind::Boolean},
                      {"sparse", Kind::Object}});
        // "Sparse Accessors": tinygltf keeps count and the offsets in an int.
        c.object(a, "sparse", at, [&](const json& s, const std::string& sat) {
            c.properties(
                s, sat,
                {{"count", Kind::Index}, {"indices", Kind::Object}, {"values", Kind::Object}});
            c.object(s, "indices", sat, [&](const json& i, const std::string& iat) {
                c.properties(i, iat,
                             {{"bufferView", Kind::Index},
                              {"byteOffset", Kind::Index},
                              {"componentType", Kind::Int32}});
            });
            c.object(s, "values", sat, [&](const json& v, const std::string& vat) {
                c.properties(v, vat, {{"bufferView", Kind::Index}, {"byteOffset", Kind::Index}});
            });
        });
    });
    c.array_of_objects(root, "bufferViews", "", [&](const json& v, const std::string& at) {
        c.properties(v, at,
                     {{"buffer", Kind::Index},
                      {"byteOffset", Kind::Unsigned},
                      {"byteLength", Kind::Unsigned},
                      {"byteStride", Kind::Unsigned},
                      {"target", Kind::Int32}});
    });
    c.array_of_objects(root, "buffers", "", [&](const json& b, const std::string& at) {
        c.properties(b, at, {{"byteLength", Kind::Unsigned}, {"uri", Kind::String}});
    });
    c.array_of_objects(root, "cameras", "", [&](const json& cam, const std::string& at) {
        c.properties(cam, at, {{"type", Kind::String}, {"perspective", Kind::Object}});
        if (const auto p = cam.find("perspective"); p != cam.end())
            c.properties(*p, at + ".perspective",
                         {{"yfov", Kind::Number},
                          {"znear", Kind::Number},
                          {"zfar", Kind::Number},
                          {"aspectRatio", Kind::Number}});
    });
    // Skins and animations are ignored (one warning), but their indices are tinygltf's ints too.
    c.array_of_objects(root, "skins", "", [&](const json& s, const std::string& at) {
        c.properties(s, at,
                     {{"joints", Kind::IndexArray},
                      {"skeleton", Kind::Index},
                      {"inverseBindMatrices", Kind::Index}});
    });
    c.array_of_objects(root, "animations", "", [&](const json& a, const std::string& at) {
        c.array_of_objects(a, "channels", at, [&](const json& ch, const std::string& cat) {
            c.properties(ch, cat, {{"sampler", Kind::Index}, {"target", Kind::Object}});
            c.object(ch, "target", cat, [&](const json& t, const std::string& tat) {
                c.properties(t, tat, {{"node", Kind::Index}});
            });
        });
        c.array_of_objects(a, "samplers", at, [&](const json& s, const std::string& sat) {
            c.properties(s, sat, {{"input", Kind::Index}, {"output", Kind::Index}});
        });
    });
}

}  // namespace mcrt
