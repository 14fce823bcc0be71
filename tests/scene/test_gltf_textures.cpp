// Textured glTF import: the texture slots of materials (host/scene/gltf_materials.cpp,
// gltf_textures.cpp), their samplers and KHR_texture_transform, alpha modes, and the decoding of
// the images they use (gltf_images.cpp): every PNG colour type and depth, baseline and
// progressive JPEG, and the refusals (truncated, too large, KTX2 / WebP, out-of-range indices).
#include <stb/stb_image_write.h>
#include <zlib.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "image/jpeg_structure.h"
#include "image/png_structure.h"
#include "image_bytes.h"
#include "scene/gltf_images.h"
#include "scene/gltf_import.h"
#include "scene/texture_lookup.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

// A 2×1 RGBA PNG: opaque red, then blue at alpha 128.
Bytes red_blue_png() { return png_file(2, 8, 6, {{255, 0, 0, 255, 0, 0, 255, 128}}); }

std::string png_image(const Bytes& png) {
    return R"({"uri": ")" + data_uri("image/png", png) + R"("})";
}

void put_floats(Bytes& out, std::initializer_list<float> values) {
    for (float v : values) {
        unsigned char b[4];
        std::memcpy(b, &v, 4);
        out.insert(out.end(), b, b + 4);
    }
}

// One triangle with TEXCOORD_0 and TEXCOORD_1, one primitive per material (primitive k uses
// material k), and the images, textures and samplers given as JSON arrays.
struct TexturedGltf {
    std::string materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
    std::string textures = R"([{"source": 0}])";
    std::string images = "[" + png_image(red_blue_png()) + "]";
    std::string samplers;  // no "samplers" when empty
    std::string extra;     // more top-level properties, each followed by a comma
    size_t primitives = 1;
    // The attributes of primitive k where given (its entry not empty), else all three.
    std::vector<std::string> attributes;
    std::vector<size_t> material_of;  // primitive k's material where given, else material k
    Bytes embedded;                   // bytes after the geometry, as bufferView 4 (an image's)

    std::string text() const {
        Bytes buffer;
        put_floats(buffer, {0, 0, 0, 1, 0, 0, 0, 1, 0});        // positions, bufferView 0
        put_floats(buffer, {0, 0, 1, 0, 0, 1});                 // TEXCOORD_0, bufferView 1
        put_floats(buffer, {0, 0, 0.5f, 0, 0, 0.5f});           // TEXCOORD_1, bufferView 2
        buffer.insert(buffer.end(), {0, 0, 1, 0, 2, 0, 0, 0});  // indices, bufferView 3 (+ pad)
        buffer.insert(buffer.end(), embedded.begin(), embedded.end());
        std::string views = R"([{"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24},
            {"buffer": 0, "byteOffset": 60, "byteLength": 24},
            {"buffer": 0, "byteOffset": 84, "byteLength": 6})";
        if (!embedded.empty())
            views += R"(, {"buffer": 0, "byteOffset": 92, "byteLength": )" +
                     std::to_string(embedded.size()) + "}";
        std::string prims;
        for (size_t k = 0; k < primitives; ++k) {
            const std::string attributes_k =
                k < attributes.size() && !attributes[k].empty()
                    ? attributes[k]
                    : R"("POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2)";
            prims += std::string(k ? ", " : "") + R"({"attributes": {)" + attributes_k +
                     R"(}, "indices": 3, "material": )" +
                     std::to_string(k < material_of.size() ? material_of[k] : k) + "}";
        }
        return R"({"asset": {"version": "2.0"}, )" + extra +
               R"("scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [)" +
               prims + R"(]}],
  "materials": )" +
               materials + R"(, "textures": )" + textures + R"(, "images": )" + images +
               (samplers.empty() ? "" : R"(, "samplers": )" + samplers) + R"(,
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
                {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}],
  "bufferViews": )" +
               views + R"(],
  "buffers": [{"byteLength": )" +
               std::to_string(buffer.size()) + R"(, "uri": ")" +
               data_uri("application/octet-stream", buffer) + R"("}]})";
    }
};

struct Loaded {
    Scene scene;
    std::vector<std::string> warnings;
};

Loaded load(const TexturedGltf& g) {
    Loaded result;
    const std::string text = g.text();
    result.scene =
        load_gltf_from_memory("textured.gltf", Bytes(text.begin(), text.end()),
                              [&](const std::string& w) { result.warnings.push_back(w); });
    return result;
}

std::string refusal(const TexturedGltf& g) {
    try {
        load(g);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// decode_images over images whose encoded bytes are given, as gltf_parse.cpp keeps a uri's.
struct Decoded {
    std::vector<TextureImage> images;
    std::string error;  // the refusal, or ""
};

Decoded decode(const std::vector<Bytes>& files, std::vector<int> sources = {}, unsigned threads = 0,
               const std::vector<std::string>& mime_types = {}) {
    tinygltf::Model model;
    for (size_t k = 0; k < files.size(); ++k) {
        tinygltf::Image image;
        image.image = files[k];
        image.as_is = true;
        if (k < mime_types.size()) image.mimeType = mime_types[k];
        model.images.push_back(image);
        if (sources.size() < files.size()) sources.push_back(int(k));
    }
    const WarningSink sink;
    gltf::Diagnostics diag("decode", sink);
    Decoded result;
    try {
        result.images = gltf::decode_images(model, sources, diag, threads);
    } catch (const InputError& e) {
        result.error = e.what();
    }
    return result;
}

Bytes rgba(std::initializer_list<int> values) {
    Bytes out;
    for (int v : values) out.push_back((unsigned char)v);
    return out;
}

// A JPEG of `texels` (RGB) by stb_image_write: baseline, 4:4:4 at quality 100.
Bytes baseline_jpeg(int width, int height, const Bytes& texels) {
    Bytes out;
    stbi_write_jpg_to_func(
        [](void* context, void* data, int size) {
            auto* bytes = static_cast<Bytes*>(context);
            bytes->insert(bytes->end(), static_cast<unsigned char*>(data),
                          static_cast<unsigned char*>(data) + size);
        },
        &out, width, height, 3, texels.data(), 100);
    return out;
}

// A PNG of `width` × `height` texels whose IDAT holds `stream` as it is (a zlib stream, valid or
// not; CRCs right), `chunks` between IHDR and IDAT.
Bytes png_with_stream(uint32_t width, uint32_t height, uint8_t depth, uint8_t colour_type,
                      const Bytes& stream, const std::vector<Bytes>& chunks = {},
                      bool interlaced = false) {
    Bytes png = png_signature();
    Bytes ihdr = png_ihdr(width, height, depth, colour_type);
    if (interlaced) {  // the interlace byte, and the CRC again
        ihdr[8 + 12] = 1;
        Bytes data(ihdr.begin() + 8, ihdr.begin() + 21);
        ihdr = png_chunk("IHDR", data);
    }
    for (const Bytes& chunk : std::vector<Bytes>{ihdr})
        png.insert(png.end(), chunk.begin(), chunk.end());
    for (const Bytes& chunk : chunks) png.insert(png.end(), chunk.begin(), chunk.end());
    for (const Bytes& chunk : {png_chunk("IDAT", stream), png_chunk("IEND", {})})
        png.insert(png.end(), chunk.begin(), chunk.end());
    return png;
}

// `raw` deflated by zlib at its best compression.
Bytes deflated(const Bytes& raw) {
    uLongf size = compressBound(uLong(raw.size()));
    Bytes out(size);
    REQUIRE(compress2(out.data(), &size, raw.data(), uLong(raw.size()), 9) == Z_OK);
    out.resize(size);
    return out;
}

// The JPEG `jpeg` with its frame header (the first SOF0) edited: marker, precision, size.
Bytes with_frame(Bytes jpeg, unsigned marker, unsigned precision, unsigned width, unsigned height) {
    for (size_t at = 2; at + 9 < jpeg.size(); ++at) {
        if (jpeg[at] != 0xFF || jpeg[at + 1] != 0xC0) continue;
        jpeg[at + 1] = (unsigned char)marker;
        jpeg[at + 4] = (unsigned char)precision;
        jpeg[at + 5] = (unsigned char)(height >> 8);
        jpeg[at + 6] = (unsigned char)height;
        jpeg[at + 7] = (unsigned char)(width >> 8);
        jpeg[at + 8] = (unsigned char)width;
        return jpeg;
    }
    FAIL("no SOF0 in the JPEG");
    return jpeg;
}

Bytes read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

// ---- texture slots, samplers, texture coordinates --------------------------------------------

TEST_CASE("every texture slot reads its texture's image, colour space, sampler and texCoord",
          "[gltf][textures]") {
    TexturedGltf g;
    g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                        "metallicRoughnessTexture": {"index": 1, "texCoord": 1}},
                       "normalTexture": {"index": 1, "scale": 0.5},
                       "emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1],
                       "occlusionTexture": {"index": 1}}])";
    g.textures = R"([{"source": 0}, {"source": 1, "sampler": 0}])";
    g.images =
        "[" + png_image(red_blue_png()) + ", " + png_image(png_file(1, 8, 0, {{7}, {9}})) + "]";
    g.samplers = R"([{"magFilter": 9728, "minFilter": 9987, "wrapS": 33071, "wrapT": 33648}])";
    const Loaded l = load(g);
    const Material& m = l.scene.materials.at(0);
    REQUIRE(l.scene.images.size() == 2);  // texture 0 twice, image 1 twice: each decoded once
    CHECK(m.textured());
    CHECK(m.base_color_texture.image == 0);
    CHECK(m.base_color_texture.srgb);
    CHECK(m.base_color_texture.linear);  // no sampler: LINEAR, REPEAT
    CHECK(m.base_color_texture.wrap_s == TextureWrap::Repeat);
    CHECK(m.base_color_texture.texcoord == 0);
    CHECK(m.emissive_texture.image == 0);
    CHECK(m.emissive_texture.srgb);
    CHECK(m.metallic_roughness_texture.image == 1);
    CHECK_FALSE(m.metallic_roughness_texture.srgb);
    CHECK_FALSE(m.metallic_roughness_texture.linear);  // magFilter NEAREST
    CHECK(m.metallic_roughness_texture.wrap_s == TextureWrap::ClampToEdge);
    CHECK(m.metallic_roughness_texture.wrap_t == TextureWrap::MirroredRepeat);
    CHECK(m.metallic_roughness_texture.texcoord == 1);
    CHECK(m.normal_texture.image == 1);
    CHECK_FALSE(m.normal_texture.srgb);
    CHECK(m.normal_scale == 0.5f);
    CHECK(m.base_color_texture.row_u == glm::vec3(1, 0, 0));
    CHECK(m.base_color_texture.row_v == glm::vec3(0, 1, 0));
    // The texels as stored: RGBA widened from grey, row 0 on top.
    const TextureImage& red_blue = l.scene.images[0];
    CHECK(red_blue.width == 2);
    CHECK(red_blue.height == 1);
    CHECK(red_blue.rgba == rgba({255, 0, 0, 255, 0, 0, 255, 128}));
    CHECK(red_blue.name == "image 0");
    CHECK(l.scene.images[1].rgba == rgba({7, 7, 7, 255, 9, 9, 9, 255}));
    // Occlusion is the one slot not read, with one warning.
    REQUIRE(l.warnings.size() == 1);
    CHECK(contains(l.warnings[0], "occlusionTexture is not used"));
}

TEST_CASE("images are numbered in first use and only the used ones are decoded",
          "[gltf][textures]") {
    TexturedGltf g;
    g.primitives = 2;  // materials 0 and 1 used, material 2 not
    g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 2}}},
                      {"emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1],
                       "pbrMetallicRoughness": {"baseColorTexture": {"index": 2}}},
                      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}])";
    Bytes truncated = red_blue_png();
    truncated.resize(truncated.size() - 5);
    g.textures = R"([{"source": 0}, {"source": 1}, {"source": 2}])";
    g.images = "[" + png_image(png_file(1, 8, 0, {{1}})) + ", " + png_image(truncated) + ", " +
               png_image(png_file(1, 8, 0, {{2}})) + "]";
    const Loaded l = load(g);
    REQUIRE(l.scene.images.size() == 2);
    CHECK(l.scene.images[0].rgba == rgba({2, 2, 2, 255}));  // glTF image 2, first used
    CHECK(l.scene.images[1].rgba == rgba({1, 1, 1, 255}));
    CHECK(l.scene.materials[0].base_color_texture.image == 0);
    CHECK(l.scene.materials[1].base_color_texture.image == 0);
    CHECK(l.scene.materials[1].emissive_texture.image == 1);
    CHECK(l.warnings.empty());
    // The unused truncated image is never decoded; used, it is refused.
    g.primitives = 3;
    CHECK(contains(refusal(g), "image 1: the PNG is truncated"));
}

TEST_CASE("samplers: wrap modes and magFilter, minFilter ignored, other values refused",
          "[gltf][textures]") {
    TexturedGltf g;
    g.textures = R"([{"source": 0, "sampler": 0}])";
    SECTION("LINEAR and absent magFilter are LINEAR") {
        for (const char* sampler :
             {R"([{"magFilter": 9729}])", R"([{"minFilter": 9728}])", "[{}]"}) {
            g.samplers = sampler;
            const TextureRef ref = load(g).scene.materials[0].base_color_texture;
            CHECK(ref.linear);
            CHECK(ref.wrap_s == TextureWrap::Repeat);
            CHECK(ref.wrap_t == TextureWrap::Repeat);
        }
    }
    SECTION("refused: a wrap or magFilter value that is none, a sampler out of range") {
        g.samplers = R"([{"wrapS": 1234}])";
        CHECK(contains(refusal(g), "sampler 0: wrapS 1234 is not a wrap mode"));
        g.samplers = R"([{"wrapT": 9729}])";
        CHECK(contains(refusal(g), "sampler 0: wrapT 9729 is not a wrap mode"));
        g.samplers = R"([{"magFilter": 9987}])";
        CHECK(contains(refusal(g), "sampler 0: magFilter 9987 is not a filter"));
        g.samplers = R"([{"magFilter": "LINEAR"}])";
        CHECK(contains(refusal(g), "samplers[0].magFilter: expected an integer"));
        g.textures = R"([{"source": 0, "sampler": 3}])";
        g.samplers = "[{}]";
        CHECK(contains(refusal(g), "texture 0: sampler 3 out of range"));
    }
}

TEST_CASE("texCoord 0 and 1 are read; other sets are refused", "[gltf][textures]") {
    TexturedGltf g;
    g.materials =
        R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 2}}}])";
    CHECK(contains(refusal(g), "material 0 baseColorTexture: texCoord 2 is not read"));
    g.materials = R"([{"emissiveTexture": {"index": 0, "texCoord": -1}}])";
    CHECK(contains(refusal(g),
                   "materials[0].emissiveTexture.texCoord: expected an integer from 0 "
                   "to 2147483647, found -1"));
}

TEST_CASE("a texture on a TEXCOORD_n the primitive lacks is ignored there, with one warning",
          "[gltf][textures]") {
    // glTF 2.0 "Texture Data": a primitive MUST have the set its material's textures read. Read
    // anyway, every corner would sample texel (0, 0).
    TexturedGltf g;
    g.attributes = {R"("POSITION": 0, "TEXCOORD_0": 1)"};  // no TEXCOORD_1
    SECTION("each slot, its factor kept") {
        const struct {
            const char* material;
            const char* slot;
            TextureRef Material::*ref;
        } slots[] = {
            {R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1},
                 "baseColorFactor": [0.5, 0.25, 1, 1]}})",
             "baseColorTexture", &Material::base_color_texture},
            {R"({"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0, "texCoord": 1},
                 "baseColorFactor": [0.5, 0.25, 1, 1]}})",
             "metallicRoughnessTexture", &Material::metallic_roughness_texture},
            {R"({"normalTexture": {"index": 0, "texCoord": 1},
                 "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1]}})",
             "normalTexture", &Material::normal_texture},
            {R"({"emissiveTexture": {"index": 0, "texCoord": 1}, "emissiveFactor": [1, 1, 1],
                 "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1]}})",
             "emissiveTexture", &Material::emissive_texture},
        };
        for (const auto& slot : slots) {
            INFO(slot.slot);
            g.materials = std::string("[") + slot.material + "]";
            const Loaded l = load(g);
            REQUIRE(l.warnings.size() == 1);
            CHECK(contains(l.warnings[0],
                           "textured.gltf: mesh 0 primitive 0: lacks the texture "
                           "coordinates that material 0 reads for " +
                               std::string(slot.slot) + " (TEXCOORD_1); ignored"));
            REQUIRE(l.scene.triangle_material.size() == 1);
            const Material& m = l.scene.materials[l.scene.triangle_material[0]];
            CHECK_FALSE((m.*slot.ref).used());
            CHECK(m.albedo == glm::vec3(0.5f, 0.25f, 1.0f));
        }
    }
    SECTION("through KHR_texture_transform's texCoord, both ways") {
        g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 0,
                           "extensions": {"KHR_texture_transform": {"texCoord": 1}}}}}])";
        Loaded l = load(g);
        REQUIRE(l.warnings.size() == 1);
        CHECK(contains(l.warnings[0], "baseColorTexture (TEXCOORD_1)"));
        CHECK_FALSE(l.scene.materials[l.scene.triangle_material[0]].base_color_texture.used());
        // The override names a set the primitive has: the texture stays.
        g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1,
                           "extensions": {"KHR_texture_transform": {"texCoord": 0}}}}}])";
        l = load(g);
        CHECK(l.warnings.empty());
        CHECK(l.scene.materials[l.scene.triangle_material[0]].base_color_texture.used());
    }
    SECTION("a primitive without any texture coordinates, several slots named at once") {
        g.attributes = {R"("POSITION": 0)"};
        g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                           "normalTexture": {"index": 0}, "name": "Floor"}])";
        const Loaded l = load(g);
        REQUIRE(l.warnings.size() == 1);
        CHECK(contains(l.warnings[0],
                       "material 0 (\"Floor\") reads for baseColorTexture "
                       "(TEXCOORD_0), normalTexture (TEXCOORD_0); ignored"));
        const Material& m = l.scene.materials[l.scene.triangle_material[0]];
        CHECK_FALSE(m.base_color_texture.used());
        CHECK_FALSE(m.normal_texture.used());
        CHECK(m.name == "Floor");
    }
    SECTION("one material on primitives with and without the set: each sees its own") {
        g.primitives = 3;
        g.material_of = {0, 0, 0};
        g.attributes = {"", R"("POSITION": 0, "TEXCOORD_0": 1)", R"("POSITION": 0)"};
        g.materials =
            R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}}])";
        const Loaded l = load(g);
        REQUIRE(l.warnings.size() == 1);  // one warning for both primitives
        CHECK(contains(l.warnings[0], "mesh 0 primitive 1: lacks"));
        CHECK(contains(l.warnings[0], "; the same on 1 more primitive(s)"));
        REQUIRE(l.scene.triangle_material.size() == 3);
        CHECK(l.scene.materials[l.scene.triangle_material[0]].base_color_texture.used());
        CHECK_FALSE(l.scene.materials[l.scene.triangle_material[1]].base_color_texture.used());
        // The copy without the texture is made once, and shared.
        CHECK(l.scene.materials.size() == 2);
        CHECK(l.scene.triangle_material[2] == l.scene.triangle_material[1]);
        CHECK(l.scene.images.size() == 1);
    }
    SECTION("instances of one primitive are one primitive in the warning") {
        g.materials =
            R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}}])";
        std::string text = g.text();
        for (const auto& [from, to] :
             {std::pair<std::string, std::string>{R"("scenes": [{"nodes": [0]}])",
                                                  R"("scenes": [{"nodes": [0, 1]}])"},
              {R"("nodes": [{"mesh": 0}])",
               R"("nodes": [{"mesh": 0}, {"mesh": 0, "translation": [0, 0, 1]}])"}}) {
            const size_t at = text.find(from);
            REQUIRE(at != std::string::npos);
            text.replace(at, from.size(), to);
        }
        std::vector<std::string> warnings;
        const Scene scene =
            load_gltf_from_memory("textured.gltf", Bytes(text.begin(), text.end()),
                                  [&](const std::string& w) { warnings.push_back(w); });
        CHECK(scene.triangle_count() == 2);
        REQUIRE(warnings.size() == 1);
        CHECK_FALSE(contains(warnings[0], "more primitive"));
    }
    SECTION("an occlusion texture on a missing set: only the occlusion warning (it is not read)") {
        g.materials = R"([{"occlusionTexture": {"index": 0, "texCoord": 1}}])";
        const Loaded l = load(g);
        REQUIRE(l.warnings.size() == 1);
        CHECK(contains(l.warnings[0], "occlusionTexture is not used"));
    }
}

TEST_CASE("KHR_texture_transform: T(offset) R(rotation) S(scale) and its texCoord, on every slot",
          "[gltf][textures]") {
    TexturedGltf g;
    SECTION("the extension's example: the lower-left quadrant, turned clockwise") {
        // KHR_texture_transform README, "Example JSON": offset [0, 1], rotation π/2, scale
        // [0.5, 0.5] uses only the image's lower-left quadrant.
        g.materials = R"([{"normalTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                           {"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}}}}])";
        const TextureRef ref = load(g).scene.materials[0].normal_texture;
        CHECK(ref.row_u.x == Approx(0.0).margin(1e-9));
        CHECK(ref.row_u.y == 0.5f);
        CHECK(ref.row_u.z == 0.0f);
        CHECK(ref.row_v.x == -0.5f);
        CHECK(ref.row_v.y == Approx(0.0).margin(1e-9));
        CHECK(ref.row_v.z == 1.0f);
        // On a 2×2 image read NEAREST, every point of [0, 1)² lands in texel (0, 1), the
        // lower-left one (row 0 is the top).
        TextureImage quadrants;
        quadrants.width = quadrants.height = 2;
        quadrants.rgba = rgba({1, 0, 0, 255, 2, 0, 0, 255, 3, 0, 0, 255, 4, 0, 0, 255});
        TextureRef nearest = ref;
        nearest.linear = false;
        for (float u : {0.05f, 0.3f, 0.7f, 0.95f}) {
            for (float v : {0.05f, 0.3f, 0.7f, 0.95f}) {
                CHECK(texture_lookup(quadrants, nearest, {u, v}).r == 3.0f / 255.0f);
            }
        }
    }
    SECTION("rotation turns the UVs counter-clockwise: R = [cos sin; −sin cos]") {
        g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
                           "extensions": {"KHR_texture_transform": {"rotation": 0.5,
                                                                    "scale": [2, 3]}}}}}])";
        const TextureRef ref = load(g).scene.materials[0].base_color_texture;
        const double c = std::cos(0.5), s = std::sin(0.5);
        CHECK(ref.row_u == glm::vec3(float(c * 2), float(s * 3), 0.0f));
        CHECK(ref.row_v == glm::vec3(float(-s * 2), float(c * 3), 0.0f));
    }
    SECTION("its texCoord overrides the textureInfo's") {
        g.materials = R"([{"emissiveTexture": {"index": 0, "texCoord": 0, "extensions":
                           {"KHR_texture_transform": {"texCoord": 1, "offset": [0.25, 0]}}}}])";
        const TextureRef ref = load(g).scene.materials[0].emissive_texture;
        CHECK(ref.texcoord == 1);
        CHECK(ref.row_u == glm::vec3(1.0f, 0.0f, 0.25f));
        g.materials = R"([{"emissiveTexture": {"index": 0, "texCoord": 1, "extensions":
                           {"KHR_texture_transform": {"texCoord": 3}}}}])";
        CHECK(contains(refusal(g), "texCoord 3 is not read"));
    }
    SECTION("malformed values are refused") {
        for (const char* transform : {R"({"offset": [1]})", R"({"scale": [1, 1, 1]})",
                                      R"({"scale": [1e39, 1]})", R"({"texCoord": 0.5})"}) {
            g.materials = std::string(R"([{"pbrMetallicRoughness": {"baseColorTexture":
                {"index": 0, "extensions": {"KHR_texture_transform": )") +
                          transform + "}}}}]";
            CHECK(contains(refusal(g), "KHR_texture_transform"));
        }
    }
    SECTION("a file may require it") {
        g.extra = R"("extensionsUsed": ["KHR_texture_transform"],
                     "extensionsRequired": ["KHR_texture_transform"],)";
        CHECK(load(g).scene.images.size() == 1);
    }
}

TEST_CASE("alphaMode, alphaCutoff and baseColorFactor's alpha", "[gltf][textures]") {
    TexturedGltf g;
    g.primitives = 4;
    g.materials = R"([{"alphaMode": "MASK", "alphaCutoff": 0.25},
                      {"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}},
                      {"alphaMode": "MASK"},
                      {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}}])";
    const Loaded l = load(g);
    CHECK(l.warnings.empty());
    const std::vector<Material>& m = l.scene.materials;
    CHECK(m[0].alpha_mode == AlphaMode::Mask);
    CHECK(m[0].alpha_cutoff == 0.25f);
    CHECK(m[0].textured());  // no texture, but a ray query must test its alpha
    CHECK(m[1].alpha_mode == AlphaMode::Blend);
    CHECK(m[1].alpha == 0.3f);
    CHECK(m[2].alpha_cutoff == 0.5f);
    CHECK(m[3].alpha_mode == AlphaMode::Opaque);
    CHECK(m[3].alpha == 0.5f);
    CHECK_FALSE(m[3].textured());

    TexturedGltf bad;
    bad.materials = R"([{"alphaMode": "MASKED"}])";
    CHECK(contains(refusal(bad), "material 0: alphaMode \"MASKED\" is not OPAQUE, MASK or BLEND"));
    bad.materials = R"([{"alphaMode": "MASK", "alphaCutoff": -0.5}])";
    CHECK(contains(refusal(bad), "alphaCutoff must be a finite number >= 0"));
    bad.materials = R"([{"alphaCutoff": "half"}])";
    CHECK(contains(refusal(bad), "materials[0].alphaCutoff: expected a number"));
}

TEST_CASE("a metallic-roughness texture does not make a Lambertian material glossy",
          "[gltf][textures]") {
    // B × metallicFactor 0 = 0: the slot is kept, the material stays Lambertian.
    TexturedGltf g;
    g.materials = R"([{"pbrMetallicRoughness": {"metallicFactor": 0,
                        "metallicRoughnessTexture": {"index": 0}},
                       "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}])";
    const Material m = load(g).scene.materials[0];
    CHECK(m.metallic_roughness_texture.used());
    CHECK(m.lambertian());
}

TEST_CASE("texture references: out of range refused, a texture without source warned about",
          "[gltf][textures]") {
    TexturedGltf g;
    g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 5}}}])";
    CHECK(
        contains(refusal(g), "textured.gltf: material 0 baseColorTexture: texture 5 out of range"));
    g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
    g.textures = R"([{"source": 3}])";
    CHECK(contains(refusal(g), "texture 0: source image 3 out of range"));
    g.textures = R"([{"source": "0"}])";
    CHECK(contains(refusal(g),
                   "textures[0].source: expected an integer from 0 to 2147483647, found a string"));
    g.textures = "[{}]";
    const Loaded l = load(g);
    CHECK_FALSE(l.scene.materials[0].base_color_texture.used());
    CHECK(l.scene.images.empty());
    REQUIRE(l.warnings.size() == 1);
    CHECK(contains(l.warnings[0], "texture 0 has no source image; the slot is left empty"));
    g.textures = R"([{"source": 0}])";
    g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"texCoord": 0}}}])";
    CHECK(contains(refusal(g), "baseColorTexture.index: required"));
}

TEST_CASE("KTX2 and WebP images are refused naming their extension; a fallback is used",
          "[gltf][textures]") {
    const Bytes ktx2 = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n', 0, 0};
    TexturedGltf g;
    g.embedded = ktx2;
    g.images =
        "[" + png_image(red_blue_png()) + R"(, {"bufferView": 4, "mimeType": "image/ktx2"}])";
    SECTION("KHR_texture_basisu without a fallback source") {
        g.textures = R"([{"extensions": {"KHR_texture_basisu": {"source": 1}}}])";
        CHECK(contains(refusal(g), "texture 0: its image comes with KHR_texture_basisu"));
    }
    SECTION("KHR_texture_basisu with a fallback PNG: the PNG, one warning") {
        g.textures = R"([{"source": 0, "extensions": {"KHR_texture_basisu": {"source": 1}}}])";
        const Loaded l = load(g);
        REQUIRE(l.scene.images.size() == 1);
        CHECK(l.scene.images[0].width == 2);
        REQUIRE(l.warnings.size() == 1);
        CHECK(contains(l.warnings[0], "KHR_texture_basisu is not implemented; its fallback"));
    }
    SECTION("an image/ktx2 image named as the source itself") {
        g.textures = R"([{"source": 1}])";
        CHECK(contains(refusal(g), "image 1: an image of KHR_texture_basisu (image/ktx2)"));
    }
    SECTION("WebP, by mimeType or by its bytes") {
        g.embedded = {'R', 'I', 'F', 'F', 4, 0, 0, 0, 'W', 'E', 'B', 'P'};
        g.images = R"([{"bufferView": 4, "mimeType": "image/png"}])";
        CHECK(contains(refusal(g), "image 0: an image of EXT_texture_webp (image/webp)"));
        g.textures = R"([{"extensions": {"EXT_texture_webp": {"source": 0}}}])";
        CHECK(contains(refusal(g), "texture 0: its image comes with EXT_texture_webp"));
    }
}

TEST_CASE("an image in a bufferView is read once the view is checked against its buffer",
          "[gltf][textures]") {
    TexturedGltf g;
    g.embedded = png_file(1, 8, 2, {{10, 20, 30}});
    g.images = R"([{"bufferView": 4, "mimeType": "image/png"}])";
    const Loaded l = load(g);
    REQUIRE(l.scene.images.size() == 1);
    CHECK(l.scene.images[0].rgba == rgba({10, 20, 30, 255}));
    CHECK(l.scene.images[0].name == "image 0");
    // A view past the buffer's end (tinygltf hands over the pointer unchecked).
    std::string text = g.text();
    const std::string view = R"("byteOffset": 92, "byteLength": )";
    const size_t at = text.find(view);
    REQUIRE(at != std::string::npos);
    text.replace(at, view.size(), R"("byteOffset": 92000, "byteLength": )");
    try {
        load_gltf_from_memory("textured.gltf", Bytes(text.begin(), text.end()), nullptr);
        FAIL("loaded");
    } catch (const InputError& e) {
        CHECK(contains(e.what(), "bufferView 4: bytes 92000 + "));
    }
}

// ---- decoding --------------------------------------------------------------------------------

TEST_CASE("PNG: every colour type and depth widened to 8-bit RGBA", "[textures][png]") {
    SECTION("grey, grey + alpha, RGB, RGBA at 8 bits") {
        const Decoded d =
            decode({png_file(2, 8, 0, {{0, 200}}), png_file(1, 8, 4, {{50, 60}}),
                    png_file(1, 8, 2, {{1, 2, 3}}), png_file(1, 8, 6, {{4, 5, 6, 7}})});
        REQUIRE(d.error.empty());
        CHECK(d.images[0].rgba == rgba({0, 0, 0, 255, 200, 200, 200, 255}));
        CHECK(d.images[1].rgba == rgba({50, 50, 50, 60}));
        CHECK(d.images[2].rgba == rgba({1, 2, 3, 255}));
        CHECK(d.images[3].rgba == rgba({4, 5, 6, 7}));
    }
    SECTION("palette, with tRNS alpha for the entries it lists") {
        const Bytes plte = png_chunk("PLTE", {10, 20, 30, 40, 50, 60, 70, 80, 90});
        const Bytes trns = png_chunk("tRNS", {128});
        const Decoded d = decode(
            {png_file(3, 8, 3, {{0, 1, 2}}, {plte}), png_file(3, 8, 3, {{2, 1, 0}}, {plte, trns})});
        REQUIRE(d.error.empty());
        CHECK(d.images[0].rgba == rgba({10, 20, 30, 255, 40, 50, 60, 255, 70, 80, 90, 255}));
        CHECK(d.images[1].rgba == rgba({70, 80, 90, 255, 40, 50, 60, 255, 10, 20, 30, 128}));
    }
    SECTION("16-bit samples keep their high byte; 1-bit grey spans 0 to 255") {
        const Decoded d =
            decode({png_file(1, 16, 6, {{0xAB, 0xCD, 0x12, 0x34, 0xFF, 0x00, 0x80, 0xFF}}),
                    png_file(1, 16, 0, {{0x7F, 0xFF}}), png_file(8, 1, 0, {{0xA5}})});
        REQUIRE(d.error.empty());
        CHECK(d.images[0].rgba == rgba({0xAB, 0x12, 0xFF, 0x80}));
        CHECK(d.images[1].rgba == rgba({0x7F, 0x7F, 0x7F, 255}));
        CHECK(d.images[2].rgba ==
              rgba({255, 255, 255, 255, 0,   0,   0, 255, 255, 255, 255, 255, 0,   0,  0, 255, 0, 0,
                    0,   255, 255, 255, 255, 255, 0, 0,   0,   255, 255, 255, 255, 255}));
    }
    SECTION("gAMA, cHRM, sRGB and iCCP are ignored: the texels as stored") {
        // TextureEncodingTest: colour metadata must not change the values a texture holds.
        const std::vector<Bytes> metadata = {
            png_chunk("gAMA", {0, 0, 0x3A, 0x98}),  // 1/2.2... as 0.15000
            png_chunk("cHRM", Bytes(32, 1)), png_chunk("sRGB", {0}),
            png_chunk("iCCP", {'x', 0, 0, 0x78, 0x01, 0x01, 0x00, 0x00, 0xFF, 0xFF})};
        const Bytes plain = png_file(2, 8, 2, {{0, 128, 255, 37, 38, 39}});
        const Bytes tagged = png_file(2, 8, 2, {{0, 128, 255, 37, 38, 39}}, metadata);
        const Decoded d = decode({plain, tagged});
        REQUIRE(d.error.empty());
        CHECK(d.images[1].rgba == d.images[0].rgba);
        CHECK(d.images[1].rgba == rgba({0, 128, 255, 255, 37, 38, 39, 255}));
    }
    SECTION("a large image on one thread and on several: the same texels") {
        std::vector<Bytes> rows(300, Bytes(3 * 257));
        for (size_t j = 0; j < rows.size(); ++j)
            for (size_t i = 0; i < rows[j].size(); ++i)
                rows[j][i] = (unsigned char)(i * 7 + j * 13);
        const std::vector<Bytes> files(6, png_file(257, 8, 2, rows));
        const Decoded one = decode(files, {}, 1), many = decode(files, {}, 4);
        REQUIRE(one.error.empty());
        REQUIRE(many.error.empty());
        for (size_t k = 0; k < files.size(); ++k) CHECK(many.images[k].rgba == one.images[0].rgba);
        CHECK(one.images[0].rgba[4 * 257 * 299 + 4 * 256] == (unsigned char)(768 * 7 + 299 * 13));
    }
}

TEST_CASE("JPEG: baseline and progressive", "[textures][jpeg]") {
    SECTION("baseline (stb_image_write, 4:4:4 at quality 100)") {
        Bytes texels;
        for (int k = 0; k < 64; ++k) texels.insert(texels.end(), {200, 100, 50});
        const Decoded d = decode({baseline_jpeg(8, 8, texels)});
        REQUIRE(d.error.empty());
        REQUIRE(d.images[0].width == 8);
        for (size_t t = 0; t < 64; ++t) {
            CHECK(std::abs(int(d.images[0].rgba[4 * t + 0]) - 200) <= 2);
            CHECK(std::abs(int(d.images[0].rgba[4 * t + 1]) - 100) <= 2);
            CHECK(std::abs(int(d.images[0].rgba[4 * t + 2]) - 50) <= 2);
            CHECK(d.images[0].rgba[4 * t + 3] == 255);
        }
    }
    SECTION("progressive (tests/data/progressive_16x16.jpg, 10 scans: cjpeg -progressive)") {
        // Texel (x, y) of the source was (16x + 8, 16y + 8, 128).
        const Decoded d =
            decode({read_file(std::string(MCRT_TEST_DATA) + "/progressive_16x16.jpg")});
        REQUIRE(d.error.empty());
        REQUIRE(d.images[0].width == 16);
        REQUIRE(d.images[0].height == 16);
        int worst = 0;
        for (int y = 0; y < 16; ++y) {
            for (int x = 0; x < 16; ++x) {
                const unsigned char* t = &d.images[0].rgba[size_t(4 * (16 * y + x))];
                worst = std::max({worst, std::abs(t[0] - (16 * x + 8)),
                                  std::abs(t[1] - (16 * y + 8)), std::abs(t[2] - 128)});
                CHECK(t[3] == 255);
            }
        }
        CHECK(worst <= 4);
    }
}

TEST_CASE("damaged or oversized images are refused with one line naming them",
          "[textures][hostile]") {
    const Bytes good = red_blue_png();
    SECTION("truncated PNGs, wherever they are cut") {
        for (size_t keep : {size_t(8), size_t(20), size_t(40), good.size() - 12, good.size() - 1}) {
            const Bytes cut(good.begin(), good.begin() + long(keep));
            const std::string error = decode({cut}).error;
            INFO("kept " << keep << " bytes: " << error);
            CHECK((contains(error, "decode: image 0: the PNG is truncated") ||
                   contains(error, "does not start with a whole IHDR chunk")));
        }
    }
    SECTION("a damaged chunk: its CRC") {
        // IDAT starts at byte 33, after the signature (8) and IHDR (25).
        Bytes flipped = good;
        flipped[33 + 8 + 2] ^= 0xFF;  // the first stored block's header
        CHECK(
            contains(decode({flipped}).error, "image 0: PNG chunk IDAT at byte 33: CRC mismatch"));
        flipped = good;
        flipped[flipped.size() - 20] ^= 0x01;  // a texel's byte in the stored block
        CHECK(contains(decode({flipped}).error, "PNG chunk IDAT at byte 33: CRC mismatch"));
        // An ancillary chunk too: its bytes are as damaged as the others.
        Bytes tagged = png_file(2, 8, 6, {{255, 0, 0, 255, 0, 0, 255, 128}},
                                {png_chunk("gAMA", {0, 0, 0xB1, 0x8F})});
        tagged[33 + 8] ^= 0x01;
        CHECK(contains(decode({tagged}).error, "PNG chunk gAMA at byte 33: CRC mismatch"));
        tagged[33 + 8] ^= 0x01;
        CHECK(decode({tagged}).error.empty());
    }
    SECTION("damaged image data behind a right CRC: Adler-32, zlib, filter types") {
        const Bytes raw = {0, 255, 0, 0, 255, 0, 0, 255, 128};  // one row, filter 0
        Bytes stream = zlib_stored(raw);
        CHECK(decode({png_with_stream(2, 1, 8, 6, stream)}).error.empty());
        stream[7 + 3] ^= 0x10;  // a texel's byte in the stored block: only Adler-32 sees it
        CHECK(contains(decode({png_with_stream(2, 1, 8, 6, stream)}).error,
                       "image 0: the PNG's image data fails its Adler-32 check"));
        stream = zlib_stored(raw);
        stream[2 + 3] ^= 0xFF;  // the stored block's length check (NLEN)
        CHECK(contains(decode({png_with_stream(2, 1, 8, 6, stream)}).error,
                       "image 0: the PNG's IDAT data is not a valid zlib stream: invalid stored "
                       "block lengths"));
        stream = zlib_stored(raw);
        stream.resize(stream.size() - 6);  // cut inside the stream
        CHECK(contains(decode({png_with_stream(2, 1, 8, 6, stream)}).error,
                       "the PNG's IDAT data ends inside its zlib stream"));
        Bytes filter = raw;
        filter[0] = 5;
        CHECK(contains(decode({png_with_stream(2, 1, 8, 6, zlib_stored(filter))}).error,
                       "image 0: the PNG's row 0 has filter type 5 (PNG defines 0 to 4)"));
    }
    SECTION("image data that inflates to more or less than the declared size needs") {
        // 16 × 16 RGBA needs 16 × (1 + 64) = 1040 bytes. Followed by 8 MiB of zeros, which
        // deflate to about 8 KiB, it would cost stb_image 8 MiB (1 GiB from 1 MB of IDAT); it is
        // refused at the first 64 KiB past the size.
        Bytes raw(16 * 65, 0);
        Bytes more = raw;
        more.resize(more.size() + (size_t(8) << 20), 0);
        const Bytes bomb = png_with_stream(16, 16, 8, 6, deflated(more));
        CHECK(bomb.size() < 20000);
        CHECK(contains(decode({bomb}).error,
                       "image 0: the PNG's IDAT data inflates beyond the 1040 bytes its 16 × 16 "
                       "texels need"));
        raw.resize(raw.size() - 65);
        CHECK(contains(decode({png_with_stream(16, 16, 8, 6, deflated(raw))}).error,
                       "image 0: the PNG's IDAT data inflates to 975 bytes; its 16 × 16 texels "
                       "need 1040"));
        raw.resize(raw.size() + 65);
        CHECK(decode({png_with_stream(16, 16, 8, 6, deflated(raw))}).error.empty());
    }
    SECTION("palette indices beyond the palette, through every filter and interlaced") {
        const Bytes palette = png_chunk("PLTE", {10, 20, 30, 40, 50, 60});  // 2 colours
        // 8-bit indices 0 1 1 0, then 1 1 1 1 stored with the Sub filter (deltas 1 0 0 0).
        const Bytes ok = {0, 0, 1, 1, 0, 1, 1, 0, 0, 0};
        const Decoded d = decode({png_with_stream(4, 2, 8, 3, zlib_stored(ok), {palette})});
        INFO(d.error);
        REQUIRE(d.error.empty());
        CHECK(d.images[0].rgba[4 * 5] == 40);
        for (unsigned filter = 0; filter <= 4; ++filter) {
            INFO("filter " << filter);
            // Row 0 indices 0 1 1 0; row 1 indices 1 1 2 1 written with `filter`.
            const Bytes row0 = {0, 1, 1, 0}, target = {1, 1, 2, 1};
            Bytes stored = {0, 0, 1, 1, 0, (unsigned char)filter};
            for (size_t i = 0; i < 4; ++i) {
                const int a = i ? target[i - 1] : 0, b = row0[i], c = i ? row0[i - 1] : 0;
                const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b),
                          pc = std::abs(p - c);
                const int predictor[5] = {0, a, b, (a + b) / 2,
                                          pa <= pb && pa <= pc ? a
                                          : pb <= pc           ? b
                                                               : c};
                stored.push_back((unsigned char)(target[i] - predictor[filter]));
            }
            CHECK(contains(
                decode({png_with_stream(4, 2, 8, 3, zlib_stored(stored), {palette})}).error,
                "image 0: the PNG's texel (2, 1) has palette index 2, beyond its "
                "2-colour palette"));
        }
        // 2-bit indices, packed: 0 1 3 0 in one byte (0b00011100).
        CHECK(
            contains(decode({png_with_stream(4, 1, 2, 3, zlib_stored({0, 0x1C}), {palette})}).error,
                     "texel (2, 0) has palette index 3"));
        // The padding bits of a row's last byte are not texels: 0 1 in the top 4 bits, 3 3 after.
        CHECK(
            decode({png_with_stream(2, 1, 2, 3, zlib_stored({0, 0x1F}), {palette})}).error.empty());
        // Adam7: 3 × 3 texels in passes 1 (0, 0), 2 none, 3 none, 4 (2, 0), 5 none... per PNG
        // 8.2: pass 1 texel (0,0); pass 4 (2,0); pass 5 (0,2),(2,2); pass 6 (1,0),(1,2); pass 7
        // row 1: (0,1),(1,1),(2,1). Index 2 at (1, 1), in pass 7.
        const Bytes interlaced = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 1};
        CHECK(contains(
            decode({png_with_stream(3, 3, 8, 3, zlib_stored(interlaced), {palette}, true)}).error,
            "the PNG's texel (1, 1) has palette index 2"));
        Bytes fine = interlaced;
        fine[13] = 1;
        const Decoded adam7 =
            decode({png_with_stream(3, 3, 8, 3, zlib_stored(fine), {palette}, true)});
        REQUIRE(adam7.error.empty());
        CHECK(adam7.images[0].rgba[4 * 4] == 40);  // texel (1, 1): colour 1
        CHECK(adam7.images[0].rgba[4 * 3] == 40);  // texel (0, 1)
        CHECK(adam7.images[0].rgba[0] == 10);      // texel (0, 0): colour 0
    }
    SECTION("IHDR fields PNG does not define, a palette image without PLTE") {
        CHECK(contains(decode({png_with_stream(1, 1, 3, 2, zlib_stored({0, 0}))}).error,
                       "the PNG's IHDR declares colour type 2 with bit depth 3"));
        CHECK(contains(decode({png_with_stream(1, 1, 8, 3, zlib_stored({0, 0}))}).error,
                       "the PNG is a palette image without a PLTE chunk"));
    }
    SECTION("an unknown critical chunk, or none of IHDR first") {
        Bytes odd = png_signature();
        for (const Bytes& chunk : {png_ihdr(1, 1, 8, 0), png_chunk("ABCD", {1}),
                                   png_chunk("IDAT", zlib_stored({0, 0})), png_chunk("IEND", {})})
            odd.insert(odd.end(), chunk.begin(), chunk.end());
        CHECK(contains(decode({odd}).error, "critical chunk of unknown type"));
        Bytes headless = png_signature();
        const Bytes iend = png_chunk("IEND", {});
        headless.insert(headless.end(), iend.begin(), iend.end());
        CHECK(contains(decode({headless}).error, "does not start with a whole IHDR chunk"));
    }
    SECTION("sizes beyond the limits, refused from the header alone") {
        CHECK(contains(decode({png_header_only(65536, 65536)}).error,
                       "image 0: 65536 × 65536 texels: more than the 16384 per side"));
        CHECK(contains(decode({png_header_only(16385, 1)}).error, "more than the 16384 per side"));
        CHECK(contains(decode({png_header_only(0, 4)}).error, "declares no texels"));
        // Within the limits, but too little data for what it declares: refused before stb_image
        // would allocate the 64 MiB image.
        CHECK(contains(decode({png_header_only(4096, 4096, 100)}).error,
                       "image 0: the PNG's 100 bytes of IDAT data cannot hold the 4096 × 4096 "
                       "texels it declares"));
        // 16-bit RGBA at 16384²: stb_image's image buffer would pass 2 GiB, which it refuses
        // only after inflating (and under another decoder's error).
        CHECK(contains(decode({png_with_stream(16384, 16384, 16, 6, Bytes(2100000, 0))}).error,
                       "image 0: 16384 × 16384 texels of 16-bit samples need a buffer of "
                       "2147500032 bytes, more than the 2 GiB stb_image (mcrt's decoder) "
                       "allocates at once"));
        // Four 16384² images are 2^30 texels, the budget; a fifth, even 1×1, is over it. (Each
        // IDAT is just long enough to pass for 1 GiB of deflated samples: never decoded.)
        std::vector<Bytes> five(4, png_header_only(16384, 16384, 1100000));
        five.push_back(png_header_only(1, 1, 1));
        CHECK(contains(decode(five).error,
                       "image 4: the images the materials use hold 1073741825 texels"));
    }
    SECTION("neither PNG nor JPEG, and a JPEG cut short") {
        const Bytes gif = {'G', 'I', 'F', '8', '9', 'a', 1, 0, 1, 0, 0, 0, 0};
        CHECK(contains(decode({gif}).error, "image 0: neither PNG nor JPEG"));
        CHECK(contains(decode({Bytes{'D', 'D', 'S', ' ', 0, 0}}).error, "MSFT_texture_dds"));
        CHECK(contains(decode({good}, {}, 0, {"image/ktx2"}).error, "KHR_texture_basisu"));
        Bytes texels(3 * 64, 90);
        Bytes jpeg = baseline_jpeg(8, 8, texels);
        jpeg.resize(jpeg.size() / 2);
        CHECK(contains(decode({jpeg}).error, "image 0: the JPEG cannot be decoded"));
    }
    SECTION("a JPEG whose frame declares more texels than its bytes can hold") {
        const Bytes small = baseline_jpeg(8, 8, Bytes(3 * 64, 90));
        const Bytes lying = with_frame(small, 0xC0, 8, 8192, 8192);
        CHECK(contains(decode({lying}).error,
                       "image 0: the JPEG's " + std::to_string(lying.size()) +
                           " bytes cannot hold the 8192 × 8192 texels it declares: its 3145728 "
                           "blocks of 8 × 8 need at least 393216 (a bit each)"));
        CHECK(contains(decode({with_frame(small, 0xC0, 8, 16384, 16384)}).error,
                       "cannot hold the 16384 × 16384 texels"));
        CHECK(contains(decode({with_frame(small, 0xC0, 8, 20000, 8)}).error,
                       "20000 × 8 texels: more than the 16384 per side"));
        // A real 1024 × 1024 JPEG of one colour is about 100 KiB against 49152 bytes at least.
        const Bytes flat = baseline_jpeg(1024, 1024, Bytes(3 * 1024 * 1024, 90));
        INFO("flat JPEG of " << flat.size() << " bytes");
        const Decoded d = decode({flat});
        CHECK(d.error.empty());
    }
    SECTION("JPEG codings stb_image lacks are named, not called corrupt") {
        const Bytes small = baseline_jpeg(8, 8, Bytes(3 * 64, 90));
        const struct {
            unsigned marker, precision;
            const char* why;
        } codings[] = {
            {0xC1, 12,
             "the JPEG has 12-bit samples (SOF1), which the decoder mcrt uses (stb_image) "
             "reads baseline and progressive Huffman JPEG of 8-bit samples only"},
            {0xC2, 12, "12-bit samples (SOF2)"},
            {0xC3, 8,
             "the JPEG is lossless (SOF3), a coding that the decoder mcrt uses (stb_image) "
             "reads baseline and progressive Huffman JPEG of 8-bit samples"},
            {0xC5, 8, "hierarchical (differential sequential) (SOF5)"},
            {0xC7, 16, "hierarchical lossless (SOF7)"},
            {0xC9, 8, "arithmetic-coded (extended sequential) (SOF9)"},
            {0xCA, 8, "arithmetic-coded progressive (SOF10)"},
            {0xCB, 8, "arithmetic-coded lossless (SOF11)"},
        };
        for (const auto& c : codings) {
            INFO(c.why);
            const std::string error =
                decode({with_frame(small, c.marker, c.precision, 8, 8)}).error;
            CHECK(contains(error, "image 0: the JPEG "));
            CHECK(contains(error, c.why));
            CHECK_FALSE(contains(error, "corrupt"));
        }
        // A DAC segment (arithmetic conditioning) before the frame.
        Bytes dac = {0xFF, 0xD8, 0xFF, 0xCC, 0x00, 0x04, 0x00, 0x10};
        dac.insert(dac.end(), small.begin() + 2, small.end());
        CHECK(contains(decode({dac}).error, "the JPEG is arithmetic-coded (a DAC marker)"));
        // The height in a DNL marker after the first scan: named too.
        CHECK(contains(decode({with_frame(small, 0xC0, 8, 8, 0)}).error,
                       "the JPEG's height comes after its first scan (a DNL marker)"));
        // Extended sequential Huffman of 8-bit samples is read (stb_image decodes SOF1 as SOF0).
        CHECK(decode({with_frame(small, 0xC1, 8, 8, 8)}).error.empty());
    }
    SECTION("of several bad images the first in slot order is reported, whatever the threads") {
        Bytes cut = good;
        cut.resize(30);
        const std::vector<Bytes> files = {cut, good, png_header_only(20000, 1)};
        for (unsigned threads : {1u, 3u}) {
            CHECK(contains(decode(files, {2, 1, 0}, threads).error, "image 2:"));
            CHECK(contains(decode(files, {1, 0, 2}, threads).error, "image 0:"));
        }
        // Decoding failures too (both pass the header checks): image data behind a right CRC
        // that fails its Adler-32.
        Bytes stream = zlib_stored({0, 255, 0, 0, 255, 0, 0, 255, 128});
        stream[7 + 3] ^= 0x10;
        const Bytes broken = png_with_stream(2, 1, 8, 6, stream);
        for (unsigned threads : {1u, 3u}) {
            CHECK(contains(decode({good, broken, broken}, {0, 2, 1}, threads).error, "image 2:"));
        }
    }
}

TEST_CASE("PNG scanline bytes: Adam7 passes counted texel by texel; JPEG blocks by sampling",
          "[textures][png][jpeg]") {
    // Adam7 (PNG 8.2): the pass of texel (x, y), from the 8 × 8 pattern.
    const int pattern[8][8] = {{1, 6, 4, 6, 2, 6, 4, 6}, {7, 7, 7, 7, 7, 7, 7, 7},
                               {5, 6, 5, 6, 5, 6, 5, 6}, {7, 7, 7, 7, 7, 7, 7, 7},
                               {3, 6, 4, 6, 3, 6, 4, 6}, {7, 7, 7, 7, 7, 7, 7, 7},
                               {5, 6, 5, 6, 5, 6, 5, 6}, {7, 7, 7, 7, 7, 7, 7, 7}};
    for (uint32_t w : {1u, 2u, 3u, 5u, 8u, 13u}) {
        for (uint32_t h : {1u, 2u, 4u, 7u, 9u}) {
            for (unsigned depth : {1u, 2u, 8u, 16u}) {
                PngLayout layout;
                layout.width = w;
                layout.height = h;
                layout.depth = uint8_t(depth);
                layout.colour_type = depth == 16 ? 6 : 0;
                const uint64_t bits = png_bits_per_texel(layout);
                CHECK(png_filtered_bytes(layout) == h * (1 + (w * bits + 7) / 8));
                // Each pass: its rows (those holding any of its texels), each of its texels.
                uint64_t expected = 0;
                for (int pass = 1; pass <= 7; ++pass) {
                    uint64_t columns = 0, rows = 0;
                    std::vector<uint64_t> per_row(h, 0);
                    for (uint32_t y = 0; y < h; ++y)
                        for (uint32_t x = 0; x < w; ++x)
                            per_row[y] += pattern[y % 8][x % 8] == pass;
                    for (uint32_t y = 0; y < h; ++y) {
                        if (per_row[y] == 0) continue;
                        ++rows;
                        columns = per_row[y];  // the same in every row of a pass
                    }
                    if (rows > 0) expected += rows * (1 + (columns * bits + 7) / 8);
                }
                layout.interlaced = true;
                INFO(w << " × " << h << " at " << depth << " bits");
                CHECK(png_filtered_bytes(layout) == expected);
            }
        }
    }
    // JPEG 4:2:0 (Y sampled 2 × 2): a 17 × 9 image is 3 × 2 blocks of Y (its texels) and 2 × 1 of
    // each chroma; padded to whole 16 × 16 MCUs, 32 × 16 samples of Y and 16 × 8 of each chroma.
    Bytes frame = {0xFF, 0xD8, 0xFF, 0xC0, 0, 17,   8, 0, 9,    0, 17,
                   3,    1,    0x22, 0,    2, 0x11, 1, 3, 0x11, 1};
    JpegFrame parsed;
    REQUIRE(read_jpeg_frame(frame.data(), frame.size(), parsed).empty());
    CHECK(parsed.width == 17);
    CHECK(parsed.height == 9);
    CHECK(parsed.blocks == 3 * 2 + 2 * (2 * 1));
    CHECK(jpeg_min_bytes(parsed) == 2);
    CHECK(parsed.padded_samples == 32 * 16 + 2 * (16 * 8));
}

TEST_CASE("the textured sample scenes load with every used image decoded", "[gltf][textures]") {
    struct Expected {
        const char* scene;
        size_t images;
        uint32_t width, height;  // of scene.images[0]
    };
    const Expected expected[] = {
        {"textured/BoxTextured/BoxTextured.gltf", 1, 256, 256},  // palette PNG
        {"textured/TextureSettingsTest/TextureSettingsTest.gltf", 3, 0, 0},
        {"textured/TextureEncodingTest/TextureEncodingTest.gltf", 8, 0, 0},
        {"textured/TextureLinearInterpolationTest/TextureLinearInterpolationTest.gltf", 2, 0, 0},
        {"textured/TextureTransformTest/TextureTransformTest.gltf", 5, 0, 0},
    };
    for (const Expected& e : expected) {
        const std::string path = scene_path(e.scene);
        std::vector<std::string> warnings;
        const Scene scene = load_gltf(path, [&](const std::string& w) { warnings.push_back(w); });
        INFO(e.scene);
        CHECK(warnings.empty());
        CHECK(scene.images.size() == e.images);
        if (e.width) {
            CHECK(scene.images[0].width == e.width);
            CHECK(scene.images[0].height == e.height);
        }
        for (const TextureImage& image : scene.images)
            CHECK(image.rgba.size() == size_t(4) * image.width * image.height);
    }
    SECTION("TextureEncodingTest: gAMA and iCCP variants of a 1×1 green hold the same texel") {
        const Scene scene =
            load_gltf(scene_path("textured/TextureEncodingTest/TextureEncodingTest.gltf"), nullptr);
        size_t one_by_one = 0;
        for (const TextureImage& image : scene.images) one_by_one += image.width == 1;
        CHECK(one_by_one == 6);
    }
}
