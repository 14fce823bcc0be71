// The corners' texture attributes of the glTF import (host/scene/gltf_attributes.cpp,
// gltf_accessors.cpp), MikkTSpace's tangents among them: files written here in memory, each
// checking one rule, and the textured scenes of the extended set (../shared/scenes/textured).
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "process_support.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"
#include "test_support.h"

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedShort = 5123;
constexpr int kTriangleStrip = 5;

// A 1×1 RGB PNG (128, 128, 255): a flat normal map, and a colour for any other slot.
constexpr const char* kPixelPng =
    "data:image/png;base64,"
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGNoaPgPAAODAgAApfuJAAAAAElFTkSuQmCC";

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string text;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const uint32_t n = (uint32_t(bytes[i]) << 16) |
                           (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                           (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0);
        text += digits[(n >> 18) & 63];
        text += digits[(n >> 12) & 63];
        text += i + 1 < bytes.size() ? digits[(n >> 6) & 63] : '=';
        text += i + 2 < bytes.size() ? digits[n & 63] : '=';
    }
    return text;
}

// A glTF document under construction, its binary data in one embedded buffer.
class GltfWriter {
  public:
    GltfWriter() { doc_["asset"] = {{"version", "2.0"}}; }

    // An accessor of `type` over `values`, each stored as `component_type` (integers as given:
    // already quantized), in a buffer view of its own.
    int accessor(const std::vector<double>& values, int component_type, const std::string& type,
                 bool normalized = false) {
        while (blob_.size() % 4) blob_.push_back(0);
        const size_t offset = blob_.size();
        for (double v : values) {
            if (component_type == kFloat) {
                append(static_cast<float>(v));
            } else if (component_type == kUnsignedByte) {
                append(static_cast<uint8_t>(v));
            } else {
                append(static_cast<uint16_t>(v));
            }
        }
        add("bufferViews",
            {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", blob_.size() - offset}});
        const size_t components = type == "SCALAR" ? 1 : size_t(type[3] - '0');
        json a = {{"bufferView", doc_["bufferViews"].size() - 1},
                  {"componentType", component_type},
                  {"count", values.size() / components},
                  {"type", type}};
        if (normalized) a["normalized"] = true;
        return add("accessors", a);
    }

    int vec3(const std::vector<glm::vec3>& v) {
        std::vector<double> values;
        for (const glm::vec3& p : v) values.insert(values.end(), {p.x, p.y, p.z});
        return accessor(values, kFloat, "VEC3");
    }
    int vec4(const std::vector<glm::vec4>& v) {
        std::vector<double> values;
        for (const glm::vec4& p : v) values.insert(values.end(), {p.x, p.y, p.z, p.w});
        return accessor(values, kFloat, "VEC4");
    }
    int vec2(const std::vector<glm::vec2>& v, int component_type = kFloat) {
        const double scale = component_type == kUnsignedByte    ? 255.0
                             : component_type == kUnsignedShort ? 65535.0
                                                                : 1.0;
        std::vector<double> values;
        for (const glm::vec2& p : v) {
            values.insert(values.end(), {std::round(p.x * scale * 1e6) / 1e6,
                                         std::round(p.y * scale * 1e6) / 1e6});
        }
        return accessor(values, component_type, "VEC2", component_type != kFloat);
    }
    int indices(const std::vector<uint32_t>& ids) {
        return accessor(std::vector<double>(ids.begin(), ids.end()), kUnsignedShort, "SCALAR");
    }

    // A material with `fields`; a texture slot's index 0 names the writer's one texture.
    int material(const json& fields) {
        if (!doc_.contains("textures")) {
            add("images", {{"uri", kPixelPng}});
            add("textures", {{"source", 0}});
        }
        return add("materials", fields);
    }
    int normal_mapped() { return material({{"normalTexture", {{"index", 0}}}}); }
    int base_colour_textured() {
        return material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    }

    int mesh(const json& primitive) { return add("meshes", {{"primitives", {primitive}}}); }
    int node(const json& fields) { return add("nodes", fields); }
    void scene(const std::vector<int>& nodes) {
        doc_["scenes"] = {{{"nodes", nodes}}};
        doc_["scene"] = 0;
    }

    json& doc() { return doc_; }

    std::vector<unsigned char> bytes() {
        json doc = doc_;
        doc["buffers"] = {{{"byteLength", blob_.size()},
                           {"uri", "data:application/octet-stream;base64," + base64(blob_)}}};
        const std::string text = doc.dump(1);
        return std::vector<unsigned char>(text.begin(), text.end());
    }

  private:
    template <typename T>
    void append(T value) {
        unsigned char b[sizeof value];
        std::memcpy(b, &value, sizeof value);
        blob_.insert(blob_.end(), b, b + sizeof value);
    }
    int add(const char* key, const json& item) {
        doc_[key].push_back(item);
        return static_cast<int>(doc_[key].size()) - 1;
    }

    json doc_;
    std::vector<unsigned char> blob_;
};

mcrt::Scene load(GltfWriter& g) {
    return mcrt::load_gltf_from_memory("attributes.gltf", g.bytes(), nullptr);
}

std::string load_error(GltfWriter& g) {
    try {
        load(g);
    } catch (const mcrt::InputError& e) {
        return e.what();
    }
    return "";
}

bool near(const glm::vec3& a, const glm::vec3& b, float tolerance = 1e-5f) {
    return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::vec3(tolerance)));
}

glm::vec3 front_normal(const mcrt::Scene& s, size_t t) {
    return glm::normalize(glm::cross(s.positions[3 * t + 1] - s.positions[3 * t],
                                     s.positions[3 * t + 2] - s.positions[3 * t]));
}

// The unit square in z = 0 seen from +Z, as two triangles: 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1).
const std::vector<glm::vec3> kSquare = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<uint32_t> kSquareIds = {0, 1, 2, 0, 2, 3};

// glTF's usual mapping of the square: u along +x, v down the image, i.e. along −y.
std::vector<glm::vec2> usual_uv(const std::vector<glm::vec3>& positions) {
    std::vector<glm::vec2> uv;
    for (const glm::vec3& p : positions) uv.emplace_back(p.x, 1.0f - p.y);
    return uv;
}

// Checks every corner's frame: unit normal, unit tangent orthogonal to it, w = ±1.
void check_frames(const mcrt::Scene& s) {
    REQUIRE(s.normals.size() == s.positions.size());
    REQUIRE(s.tangents.size() == s.positions.size());
    for (size_t c = 0; c < s.positions.size(); ++c) {
        INFO("corner " << c);
        const glm::vec3 t(s.tangents[c]);
        CHECK(glm::length(s.normals[c]) == Approx(1.0f).margin(1e-5));
        CHECK(glm::length(t) == Approx(1.0f).margin(1e-5));
        CHECK(std::abs(s.tangents[c].w) == 1.0f);
        CHECK(std::abs(glm::dot(t, s.normals[c])) < 1e-4f);
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Texture coordinates
// ---------------------------------------------------------------------------------------------

TEST_CASE("TEXCOORD_0 and _1 follow their corners: floats, normalized bytes and shorts",
          "[gltf][attributes]") {
    // uv0 = (0.2 x, 0.6 y), uv1 = (1 − x, y): a corner's coordinates are known from its place.
    std::vector<glm::vec2> uv0, uv1;
    for (const glm::vec3& p : kSquare) {
        uv0.emplace_back(0.2f * p.x, 0.6f * p.y);
        uv1.emplace_back(1.0f - p.x, p.y);
    }
    struct Case {
        const char* name;
        int format0, format1;
        json node;
        float mirror;  // world x = mirror · local x
    };
    const Case cases[] = {
        {"floats", kFloat, kFloat, json::object(), 1.0f},
        {"bytes, shorts", kUnsignedByte, kUnsignedShort, json::object(), 1.0f},
        {"shorts, bytes, mirrored", kUnsignedShort, kUnsignedByte, {{"scale", {-1, 1, 1}}}, -1.0f},
    };
    for (const Case& c : cases) {
        INFO(c.name);
        GltfWriter g;
        json node = c.node;
        node["mesh"] = g.mesh({{"attributes",
                                {{"POSITION", g.vec3(kSquare)},
                                 {"TEXCOORD_0", g.vec2(uv0, c.format0)},
                                 {"TEXCOORD_1", g.vec2(uv1, c.format1)}}},
                               {"indices", g.indices(kSquareIds)},
                               {"material", g.base_colour_textured()}});
        g.scene({g.node(node)});
        const mcrt::Scene s = load(g);
        REQUIRE(s.triangle_count() == 2);
        REQUIRE(s.texcoords.size() == 6);
        CHECK(s.textured());
        for (size_t k = 0; k < 6; ++k) {
            const glm::vec3 p = s.positions[k];
            const float x = c.mirror * p.x;
            CHECK(s.texcoords[k].x == Approx(0.2f * x).margin(1e-6));
            CHECK(s.texcoords[k].y == Approx(0.6f * p.y).margin(1e-6));
            CHECK(s.texcoords[k].z == Approx(1.0f - x).margin(1e-6));
            CHECK(s.texcoords[k].w == Approx(p.y).margin(1e-6));
        }
        for (size_t t = 0; t < 2; ++t) CHECK(near(front_normal(s, t), {0, 0, 1}));
        // No normal texture: no frames.
        CHECK(std::all_of(s.normals.begin(), s.normals.end(),
                          [](const glm::vec3& n) { return n == glm::vec3(0.0f); }));
    }
}

TEST_CASE("A strip's corners carry their own vertices' texture coordinates", "[gltf][attributes]") {
    // Strip 0 (0,0), 1 (1,0), 2 (0,1), 3 (1,1): triangles {0,1,2} and {1,3,2}.
    const std::vector<glm::vec3> strip = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    GltfWriter g;
    g.scene({g.node(
        {{"mesh", g.mesh({{"attributes",
                           {{"POSITION", g.vec3(strip)}, {"TEXCOORD_0", g.vec2(usual_uv(strip))}}},
                          {"mode", kTriangleStrip},
                          {"material", g.base_colour_textured()}})}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 2);
    for (size_t k = 0; k < 6; ++k) {
        CHECK(s.texcoords[k].x == Approx(s.positions[k].x));
        CHECK(s.texcoords[k].y == Approx(1.0f - s.positions[k].y));
        CHECK(s.texcoords[k].z == 0.0f);  // no TEXCOORD_1
        CHECK(s.texcoords[k].w == 0.0f);
    }
}

TEST_CASE("An untextured scene has no corner attributes; a later textured primitive gives all",
          "[gltf][attributes]") {
    GltfWriter g;
    const json plain = {{"attributes", {{"POSITION", g.vec3(kSquare)}}},
                        {"indices", g.indices(kSquareIds)}};
    const int plain_mesh = g.mesh(plain);
    g.scene({g.node({{"mesh", plain_mesh}})});
    const mcrt::Scene untextured = load(g);
    CHECK_FALSE(untextured.textured());
    CHECK(untextured.texcoords.empty());
    CHECK(untextured.normals.empty());
    CHECK(untextured.tangents.empty());

    const std::vector<glm::vec2> uv = usual_uv(kSquare);
    const int textured_mesh = g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(kSquare)},
                                        {"NORMAL", g.vec3(std::vector<glm::vec3>(4, {0, 0, 1}))},
                                        {"TEXCOORD_0", g.vec2(uv)}}},
                                      {"indices", g.indices(kSquareIds)},
                                      {"material", g.normal_mapped()}});
    g.scene({g.node({{"mesh", plain_mesh}}),
             g.node({{"mesh", textured_mesh}, {"translation", {0, 0, 1}}}),
             g.node({{"mesh", plain_mesh}, {"translation", {0, 0, 2}}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 6);
    REQUIRE(s.texcoords.size() == 18);
    REQUIRE(s.normals.size() == 18);
    REQUIRE(s.tangents.size() == 18);
    for (size_t c = 0; c < 18; ++c) {
        INFO("corner " << c);
        const bool textured = c >= 6 && c < 12;
        const glm::vec4 uv(s.positions[c].x, 1.0f - s.positions[c].y, 0.0f, 0.0f);
        CHECK(s.texcoords[c] == (textured ? uv : glm::vec4(0.0f)));
        CHECK((s.normals[c] == glm::vec3(0.0f)) == !textured);
        CHECK((s.tangents[c] == glm::vec4(0.0f)) == !textured);
    }
}

TEST_CASE("Texture coordinates that are not finite, of a wrong type or count, are refused",
          "[gltf][attributes][invalid]") {
    auto file_with = [](auto make_texcoord) {
        GltfWriter g;
        g.scene({g.node(
            {{"mesh", g.mesh({{"attributes",
                               {{"POSITION", g.vec3(kSquare)}, {"TEXCOORD_0", make_texcoord(g)}}},
                              {"indices", g.indices(kSquareIds)},
                              {"material", g.base_colour_textured()}})}})});
        return g;
    };
    GltfWriter nan = file_with([](GltfWriter& g) {
        return g.accessor({0, 0, 1, std::nan(""), 1, 1, 0, 1}, kFloat, "VEC2");
    });
    CHECK(load_error(nan) == "attributes.gltf: accessor 1: TEXCOORD_0 1 is not finite");
    GltfWriter infinite = file_with([](GltfWriter& g) {
        return g.accessor({0, 0, 1, 0, 1, 1, 0, HUGE_VAL}, kFloat, "VEC2");
    });
    CHECK(load_error(infinite) == "attributes.gltf: accessor 1: TEXCOORD_0 3 is not finite");
    GltfWriter vec3 = file_with([](GltfWriter& g) { return g.vec3(kSquare); });
    CHECK(load_error(vec3).find("accessor 1: TEXCOORD_0 must be a VEC2 of floats") !=
          std::string::npos);
    GltfWriter unnormalized_float = file_with([](GltfWriter& g) {
        return g.accessor({0, 0, 1, 0, 1, 1, 0, 1}, kFloat, "VEC2", true);
    });
    CHECK(load_error(unnormalized_float).find("TEXCOORD_0 must be a VEC2") != std::string::npos);
    GltfWriter short_count = file_with([](GltfWriter& g) {
        return g.vec2({{0, 0}, {1, 0}, {1, 1}});
    });
    CHECK(load_error(short_count) ==
          "attributes.gltf: mesh 0 primitive 0: TEXCOORD_0 (accessor 1) has 3 values, POSITION "
          "has 4");
}

TEST_CASE("A non-finite TEXCOORD makes mcrt exit 2 with one error line",
          "[gltf][attributes][cli]") {
    GltfWriter g;
    g.scene({g.node({{"mesh", g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(kSquare)},
                                        {"TEXCOORD_0",
                                         g.accessor({0, 0, 1, 0, 1, 1, 0, NAN}, kFloat, "VEC2")}}},
                                      {"indices", g.indices(kSquareIds)},
                                      {"material", g.base_colour_textured()}})}})});
    const fs::path dir =
        fs::temp_directory_path() / ("mcrt-attributes-" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "nan_texcoord.gltf";
    const std::vector<unsigned char> bytes = g.bytes();
    std::ofstream(file, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
    const mcrt::test::ProcessResult r = mcrt::test::run_process(
        MCRT_EXE, {"render", file.string(), "--out", (dir / "out.exr").string()}, dir);
    fs::remove_all(dir);
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 2);
    const std::vector<std::string> errors = mcrt::test::lines_starting_with(r.err, "mcrt: error:");
    REQUIRE(errors.size() == 1);
    CHECK(errors[0] ==
          "mcrt: error: " + file.string() + ": accessor 1: TEXCOORD_0 3 is not finite");
}

// ---------------------------------------------------------------------------------------------
// Normals and given tangents
// ---------------------------------------------------------------------------------------------

TEST_CASE("Without NORMAL the normals are the faces' and a TANGENT is ignored",
          "[gltf][attributes]") {
    // A bent strip: two triangles at an angle, rotated 90° about +X by the node.
    const std::vector<glm::vec3> bent = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 1}};
    GltfWriter g;
    const int wrong_tangents = g.vec4(std::vector<glm::vec4>(4, {0, 0, 1, -1}));
    g.scene({g.node({{"mesh", g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(bent)},
                                        {"TANGENT", wrong_tangents},
                                        {"TEXCOORD_0", g.vec2(usual_uv(bent))}}},
                                      {"indices", g.indices(kSquareIds)},
                                      {"material", g.normal_mapped()}})},
                     {"rotation", {std::sqrt(0.5), 0, 0, std::sqrt(0.5)}}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 2);
    check_frames(s);
    for (size_t c = 0; c < 6; ++c) CHECK(near(s.normals[c], front_normal(s, c / 3)));
    // Generated, not the file's: dP/du is +x on the flat triangle and (1, 0, −1)/√2 on the
    // tilted one, (x, y, z) ↦ (x, −z, y) in the world; the faces' normals differ, so no corner
    // is shared between them.
    const glm::vec3 expected[2] = {{1, 0, 0}, glm::normalize(glm::vec3(1, 1, 0))};
    for (size_t c = 0; c < 6; ++c) {
        INFO("corner " << c);
        CHECK(near(glm::vec3(s.tangents[c]), expected[c / 3]));
        CHECK(s.tangents[c].w == 1.0f);
    }
}

TEST_CASE("Given normals and tangents are carried into the world and kept", "[gltf][attributes]") {
    // Normal (1,0,1)/√2 and tangent (1,0,−1)/√2 at every vertex, under scale (2,1,1) then 90°
    // about +Z: normals go by the inverse transpose, tangents by the matrix.
    const glm::vec3 n = glm::normalize(glm::vec3(1, 0, 1)), t = glm::normalize(glm::vec3(1, 0, -1));
    GltfWriter g;
    g.scene({g.node({{"mesh", g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(kSquare)},
                                        {"NORMAL", g.vec3(std::vector<glm::vec3>(4, n))},
                                        {"TANGENT", g.vec4(std::vector<glm::vec4>(4, {t, 1}))},
                                        {"TEXCOORD_0", g.vec2(usual_uv(kSquare))}}},
                                      {"indices", g.indices(kSquareIds)},
                                      {"material", g.normal_mapped()}})},
                     {"rotation", {0, 0, std::sqrt(0.5), std::sqrt(0.5)}},
                     {"scale", {2, 1, 1}}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 2);
    check_frames(s);
    // Scale: n ∝ (0.5, 0, 1), t ∝ (2, 0, −1); then (x, y) ↦ (−y, x).
    const glm::vec3 world_n = glm::normalize(glm::vec3(0, 0.5f, 1));
    const glm::vec3 world_t = glm::normalize(glm::vec3(0, 2, -1));
    for (size_t c = 0; c < 6; ++c) {
        INFO("corner " << c);
        CHECK(near(s.normals[c], world_n));
        CHECK(near(glm::vec3(s.tangents[c]), world_t));
        CHECK(s.tangents[c].w == 1.0f);
    }
}

TEST_CASE("A mirroring node flips the handedness of given and generated tangents",
          "[gltf][attributes]") {
    for (const bool given : {true, false}) {
        INFO((given ? "given TANGENT" : "generated"));
        GltfWriter g;
        json attributes = {{"POSITION", g.vec3(kSquare)},
                           {"NORMAL", g.vec3(std::vector<glm::vec3>(4, {0, 0, 1}))},
                           {"TEXCOORD_0", g.vec2(usual_uv(kSquare))}};
        if (given) attributes["TANGENT"] = g.vec4(std::vector<glm::vec4>(4, {1, 0, 0, 1}));
        const int mesh = g.mesh({{"attributes", attributes},
                                 {"indices", g.indices(kSquareIds)},
                                 {"material", g.normal_mapped()}});
        g.scene({g.node({{"mesh", mesh}}), g.node({{"mesh", mesh}, {"scale", {-1, 1, 1}}})});
        const mcrt::Scene s = load(g);
        REQUIRE(s.triangle_count() == 4);
        check_frames(s);
        for (size_t c = 0; c < 12; ++c) {
            INFO("corner " << c);
            const bool mirrored = c >= 6;
            CHECK(near(s.normals[c], {0, 0, 1}));
            CHECK(near(front_normal(s, c / 3), {0, 0, 1}));
            CHECK(near(glm::vec3(s.tangents[c]), {mirrored ? -1.0f : 1.0f, 0, 0}));
            CHECK(s.tangents[c].w == (mirrored ? -1.0f : 1.0f));
            // Either way the bitangent w·(n × t) points up the image: +y.
            const glm::vec3 b =
                s.tangents[c].w * glm::cross(s.normals[c], glm::vec3(s.tangents[c]));
            CHECK(near(b, {0, 1, 0}));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Generated tangents
// ---------------------------------------------------------------------------------------------

TEST_CASE("Generated tangents of a planar quad follow dP/du with w = +1", "[gltf][tangents]") {
    // u at 30° in the plane: u = cos θ x + sin θ y, v = 1 − (−sin θ x + cos θ y).
    const float theta = glm::radians(30.0f);
    const glm::vec3 du(std::cos(theta), std::sin(theta), 0.0f);
    std::vector<glm::vec2> uv;
    for (const glm::vec3& p : kSquare) {
        uv.emplace_back(glm::dot(p, du), 1.0f - glm::dot(p, glm::vec3(-du.y, du.x, 0.0f)));
    }
    GltfWriter g;
    g.scene({g.node({{"mesh", g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(kSquare)},
                                        {"NORMAL", g.vec3(std::vector<glm::vec3>(4, {0, 0, 1}))},
                                        {"TEXCOORD_0", g.vec2(uv)}}},
                                      {"indices", g.indices(kSquareIds)},
                                      {"material", g.normal_mapped()}})}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 2);
    check_frames(s);
    for (size_t c = 0; c < 6; ++c) {
        INFO("corner " << c);
        CHECK(near(glm::vec3(s.tangents[c]), du));
        CHECK(s.tangents[c].w == 1.0f);
    }
}

TEST_CASE("A mirrored UV island keeps its own tangents with w = −1", "[gltf][tangents]") {
    // Two squares sharing the edge x = 1; the right one's u runs back (u = 2 − x), so the seam's
    // vertices are the same vertex (same position, normal and u = 1) on both islands.
    const std::vector<glm::vec3> positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0},
                                              {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
    std::vector<glm::vec2> uv;
    for (const glm::vec3& p : positions) uv.emplace_back(p.x <= 1 ? p.x : 2 - p.x, 1 - p.y);
    GltfWriter g;
    g.scene({g.node({{"mesh", g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(positions)},
                                        {"NORMAL", g.vec3(std::vector<glm::vec3>(6, {0, 0, 1}))},
                                        {"TEXCOORD_0", g.vec2(uv)}}},
                                      {"indices", g.indices({0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2})},
                                      {"material", g.normal_mapped()}})}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 4);
    check_frames(s);
    for (size_t c = 0; c < 12; ++c) {
        INFO("corner " << c);
        const bool right = c >= 6;
        CHECK(near(glm::vec3(s.tangents[c]), {right ? -1.0f : 1.0f, 0, 0}));
        CHECK(s.tangents[c].w == (right ? -1.0f : 1.0f));
    }
}

TEST_CASE("Generated tangents of a cylinder are the analytic ones", "[gltf][tangents]") {
    // P(φ, y) = (cos φ, y, −sin φ), u = φ / 2π, v = 1 − y, seen from outside: dP/du is
    // (−sin φ, 0, −cos φ), not mirrored. The seam (u = 0 and 1) has two vertices per point.
    const int segments = 12;
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec2> uv;
    for (int i = 0; i <= segments; ++i) {
        const float phi = 2.0f * glm::pi<float>() * float(i) / float(segments);
        for (int y = 0; y < 2; ++y) {
            positions.emplace_back(std::cos(phi), float(y), -std::sin(phi));
            normals.emplace_back(std::cos(phi), 0.0f, -std::sin(phi));
            uv.emplace_back(float(i) / float(segments), 1.0f - float(y));
        }
    }
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < uint32_t(segments); ++i) {
        const uint32_t a = 2 * i, b = 2 * i + 2;
        ids.insert(ids.end(), {a, b, b + 1, a, b + 1, a + 1});
    }
    GltfWriter g;
    g.scene({g.node({{"mesh", g.mesh({{"attributes",
                                       {{"POSITION", g.vec3(positions)},
                                        {"NORMAL", g.vec3(normals)},
                                        {"TEXCOORD_0", g.vec2(uv)}}},
                                      {"indices", g.indices(ids)},
                                      {"material", g.normal_mapped()}})}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == size_t(2 * segments));
    check_frames(s);
    for (size_t c = 0; c < s.positions.size(); ++c) {
        INFO("corner " << c);
        const glm::vec3 p = s.positions[c];
        CHECK(near(s.normals[c], glm::vec3(p.x, 0, p.z)));
        CHECK(near(glm::vec3(s.tangents[c]), glm::vec3(p.z, 0, -p.x), 1e-5f));
        CHECK(s.tangents[c].w == 1.0f);
    }
}

TEST_CASE("The normal texture's texCoord, overridden by KHR_texture_transform, drives tangents",
          "[gltf][tangents]") {
    // TEXCOORD_0 runs u along +x, TEXCOORD_1 along +y.
    std::vector<glm::vec2> uv1;
    for (const glm::vec3& p : kSquare) uv1.emplace_back(p.y, p.x);
    struct Case {
        const char* name;
        json normal_texture;
        glm::vec3 tangent;
    };
    const Case cases[] = {
        {"texCoord 0", {{"index", 0}}, {1, 0, 0}},
        {"texCoord 1", {{"index", 0}, {"texCoord", 1}}, {0, 1, 0}},
        {"transform's texCoord 1",
         {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}},
         {0, 1, 0}},
    };
    for (const Case& c : cases) {
        INFO(c.name);
        GltfWriter g;
        g.scene({g.node(
            {{"mesh",
              g.mesh({{"attributes",
                       {{"POSITION", g.vec3(kSquare)},
                        {"NORMAL", g.vec3(std::vector<glm::vec3>(4, {0, 0, 1}))},
                        {"TEXCOORD_0", g.vec2(usual_uv(kSquare))},
                        {"TEXCOORD_1", g.vec2(uv1)}}},
                      {"indices", g.indices(kSquareIds)},
                      {"material", g.material({{"normalTexture", c.normal_texture}})}})}})});
        const mcrt::Scene s = load(g);
        check_frames(s);
        // (u, v) = (y, x) turns the image a quarter (+x is down it): not mirrored either.
        for (size_t k = 0; k < 6; ++k) {
            CHECK(near(glm::vec3(s.tangents[k]), c.tangent));
            CHECK(s.tangents[k].w == 1.0f);
        }
    }
}

TEST_CASE("Merging duplicate emitters keeps the corner attributes beside their corners",
          "[gltf][attributes]") {
    // The same emissive, textured square twice, then once more moved: the copy is dropped.
    GltfWriter g;
    std::vector<glm::vec2> uv = usual_uv(kSquare);
    const int material =
        g.material({{"emissiveFactor", {1, 1, 1}}, {"emissiveTexture", {{"index", 0}}}});
    const int mesh =
        g.mesh({{"attributes", {{"POSITION", g.vec3(kSquare)}, {"TEXCOORD_0", g.vec2(uv)}}},
                {"indices", g.indices(kSquareIds)},
                {"material", material}});
    g.scene({g.node({{"mesh", mesh}}), g.node({{"mesh", mesh}}),
             g.node({{"mesh", mesh}, {"translation", {3, 0, 0}}})});
    const mcrt::Scene s = load(g);
    REQUIRE(s.triangle_count() == 4);
    REQUIRE(s.texcoords.size() == 12);
    REQUIRE(s.normals.size() == 12);
    REQUIRE(s.tangents.size() == 12);
    for (size_t c = 0; c < 12; ++c) {
        const float x = s.positions[c].x >= 3 ? s.positions[c].x - 3 : s.positions[c].x;
        CHECK(s.texcoords[c].x == Approx(x));
        CHECK(s.texcoords[c].y == Approx(1 - s.positions[c].y));
    }
}

// ---------------------------------------------------------------------------------------------
// The textured scenes of the extended set (../shared/scenes/textured: Sponza's 55 MB among them)
// ---------------------------------------------------------------------------------------------

namespace {

// The file's JSON with every primitive's TANGENT removed.
std::vector<unsigned char> without_tangents(const std::vector<unsigned char>& gltf) {
    json doc = json::parse(gltf.begin(), gltf.end());
    for (json& mesh : doc["meshes"])
        for (json& primitive : mesh["primitives"]) primitive["attributes"].erase("TANGENT");
    const std::string text = doc.dump();
    return std::vector<unsigned char>(text.begin(), text.end());
}

// Primitives of the default scene's meshes with a normal texture, and how many of those have
// NORMAL and TANGENT (those keep the file's tangents).
struct NormalMapped {
    size_t primitives = 0, with_tangents = 0;
};
NormalMapped normal_mapped_primitives(const json& doc) {
    NormalMapped count;
    if (!doc.contains("meshes")) return count;
    for (const json& mesh : doc["meshes"]) {
        for (const json& primitive : mesh["primitives"]) {
            if (!primitive.contains("material")) continue;
            const json& material = doc["materials"][primitive["material"].get<size_t>()];
            if (!material.contains("normalTexture")) continue;
            ++count.primitives;
            const json& a = primitive["attributes"];
            if (a.contains("NORMAL") && a.contains("TANGENT")) ++count.with_tangents;
        }
    }
    return count;
}

}  // namespace

TEST_CASE("Textured sample scenes: attributes parallel to positions, frames orthonormal",
          "[gltf][attributes][textured][extended]") {
    const fs::path root = mcrt::test::extended_scene("textured");
    std::vector<fs::path> files;
    for (const auto& dir : fs::directory_iterator(root)) {
        if (!dir.is_directory()) continue;
        for (const auto& f : fs::directory_iterator(dir.path()))
            if (f.path().extension() == ".gltf") files.push_back(f.path());
    }
    std::sort(files.begin(), files.end());
    REQUIRE(files.size() >= 16);

    std::ostringstream report;
    report << "scene | triangles | normal-mapped primitives | tangents | load s | load s, all "
              "generated | generated vs file tangents (corners within 1°, same w)\n";
    for (const fs::path& file : files) {
        INFO(file.string());
        mcrt::FileBundle record;
        const auto start = std::chrono::steady_clock::now();
        const mcrt::Scene s = mcrt::load_gltf(file.string(), nullptr, nullptr, &record);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        REQUIRE(record.count(file.string()) == 1);
        const json doc = json::parse(record[file.string()].begin(), record[file.string()].end());
        const NormalMapped mapped = normal_mapped_primitives(doc);

        REQUIRE(s.textured());
        REQUIRE(s.texcoords.size() == s.positions.size());
        REQUIRE(s.normals.size() == s.positions.size());
        REQUIRE(s.tangents.size() == s.positions.size());
        size_t framed = 0, bad = 0;
        for (size_t c = 0; c < s.positions.size(); ++c) {
            if (s.normals[c] == glm::vec3(0.0f)) continue;
            ++framed;
            const glm::vec3 t(s.tangents[c]);
            const bool unit = std::abs(glm::length(s.normals[c]) - 1.0f) < 1e-4f &&
                              std::abs(glm::length(t) - 1.0f) < 1e-4f;
            if (!unit || std::abs(s.tangents[c].w) != 1.0f) ++bad;
        }
        CHECK(bad == 0);
        CHECK((framed > 0) == (mapped.primitives > 0));

        // Where the file has tangents, ours from MikkTSpace against them.
        std::string agreement = "-", generated_seconds = "-";
        if (mapped.with_tangents > 0) {
            mcrt::FileBundle stripped = record;
            stripped[file.string()] = without_tangents(record[file.string()]);
            const auto generated_start = std::chrono::steady_clock::now();
            const mcrt::Scene generated =
                mcrt::load_gltf_from_bundle(file.string(), stripped, nullptr);
            generated_seconds = std::to_string(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - generated_start)
                    .count());
            REQUIRE(generated.tangents.size() == s.tangents.size());
            size_t compared = 0, close = 0;
            for (size_t c = 0; c < s.tangents.size(); ++c) {
                if (s.normals[c] == glm::vec3(0.0f)) continue;
                ++compared;
                const float cosine =
                    glm::dot(glm::vec3(s.tangents[c]), glm::vec3(generated.tangents[c]));
                if (cosine > std::cos(glm::radians(1.0f)) &&
                    s.tangents[c].w == generated.tangents[c].w) {
                    ++close;
                }
            }
            std::ostringstream text;
            text.precision(4);
            text << 100.0 * double(close) / double(std::max<size_t>(compared, 1)) << " % of "
                 << compared;
            agreement = text.str();
        }
        const char* tangents = mapped.primitives == 0                      ? "none"
                               : mapped.with_tangents == mapped.primitives ? "file"
                               : mapped.with_tangents == 0                 ? "generated"
                                                                           : "file + generated";
        report << file.stem().string() << " | " << s.triangle_count() << " | " << mapped.primitives
               << " | " << tangents << " | " << seconds << " | " << generated_seconds << " | "
               << agreement << "\n";
    }
    std::cout << report.str();
}
