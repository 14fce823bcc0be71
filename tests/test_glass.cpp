// Glass: KHR_materials_ior, _transmission and _volume (kernels/bsdf.cl, -D MCRT_TRANSMISSION):
// what the importer reads and refuses, the F0 the index of refraction gives every dielectric,
// and scenes without these extensions unchanged.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "common/error.h"
#include "image_bytes.h"
#include "bvh/bvh.h"
#include "render/gpu_scene.h"
#include "scene/gltf_import.h"
#include "scene_builders.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

// ---- One triangle with a material written in JSON ----------------------------------------------

std::string triangle_gltf(const std::string& material) {
    const float p[9] = {-1, 0, 1, 1, 0, 1, 0, 0, -1};
    const uint16_t indices[3] = {0, 1, 2};
    Bytes bytes(sizeof p + sizeof indices);
    std::memcpy(bytes.data(), p, sizeof p);
    std::memcpy(bytes.data() + sizeof p, indices, sizeof indices);
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}], "materials": [)" +
           material + R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0},
        "indices": 1, "material": 0}]}],
        "buffers": [{"byteLength": 42, "uri": "data:application/octet-stream;base64,)" +
           base64(bytes) + R"("}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [-1, 0, -1], "max": [1, 0, 1]},
                      {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
}

struct Loaded {
    Material material;
    std::vector<std::string> warnings;
};

// The material of `extensions` (the JSON object's members) on a dielectric (metallic 0).
Loaded load_material(const std::string& extensions) {
    const std::string text = triangle_gltf(
        R"({"pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": {)" + extensions + "}}");
    Loaded l;
    Scene s = load_gltf_from_memory("glass.gltf", std::vector<unsigned char>(text.begin(), text.end()),
                                    [&](const std::string& w) { l.warnings.push_back(w); });
    l.material = s.materials.at(0);
    return l;
}

std::string refusal(const std::string& extensions) {
    try {
        load_material(extensions);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

// The dielectric's F0 as the host packs it for the kernels (host/render/gpu_scene.cpp).
glm::vec4 packed_specular(const Material& m) {
    Scene s;
    s.materials.push_back(m);
    add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    const gpu::float4 v = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1).materials[0].specular;
    return glm::vec4(v.x, v.y, v.z, v.w);
}

}  // namespace

// ---- KHR_materials_ior ------------------------------------------------------------------------

TEST_CASE("KHR_materials_ior sets every dielectric's F0; ior 1.5 gives exactly 0.04",
          "[glass][ior]") {
    SECTION("absent: 1.5, and the F0 the kernels had before the extension, to the bit") {
        const Loaded l = load_material("");
        CHECK(l.warnings.empty());
        CHECK(l.material.ior == 1.5f);
        const glm::vec4 f = packed_specular(l.material);
        CHECK(f.x == 0.04f);
        CHECK(f.w == 1.0f);
    }
    SECTION("F0 = ((ior - 1)/(ior + 1))^2, times KHR_materials_specular's colour and factor") {
        const Loaded l = load_material(R"("KHR_materials_ior": {"ior": 1.33},
            "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 2, 0.5]})");
        CHECK(l.warnings.empty());
        REQUIRE(l.material.ior == 1.33f);
        const double f0 = std::pow((1.33 - 1.0) / (1.33 + 1.0), 2.0);
        const glm::vec4 f = packed_specular(l.material);
        CHECK(f.x == Approx(f0 * 0.5).epsilon(1e-6));
        CHECK(f.y == Approx(2.0 * f0 * 0.5).epsilon(1e-6));
        CHECK(f.z == Approx(0.5 * f0 * 0.5).epsilon(1e-6));
        CHECK(f.w == 0.5f);
    }
    SECTION("ior 0 is the extension's specular-glossiness mode: F0 = 1") {
        const Loaded l = load_material(R"("KHR_materials_ior": {"ior": 0})");
        CHECK(l.warnings.empty());
        CHECK(l.material.ior == 0.0f);
        CHECK(packed_specular(l.material).x == 1.0f);
    }
    SECTION("below 1 (not 0): the default with one warning; huge: clamped with one warning") {
        for (const char* bad : {"-2", "0.5", "1e-30"}) {
            INFO(bad);
            const Loaded l = load_material(std::string(R"("KHR_materials_ior": {"ior": )") + bad + "}");
            REQUIRE(l.warnings.size() == 1);
            CHECK(l.warnings[0].find("KHR_materials_ior.ior") != std::string::npos);
            CHECK(l.material.ior == 1.5f);
        }
        const Loaded huge = load_material(R"("KHR_materials_ior": {"ior": 1e300})");
        REQUIRE(huge.warnings.size() == 1);
        CHECK(huge.warnings[0].find("clamped") != std::string::npos);
        CHECK(huge.material.ior == 1e4f);
        const glm::vec4 f = packed_specular(huge.material);
        CHECK(std::isfinite(f.x));
        CHECK(f.x > 0.999f);
    }
    SECTION("not a finite number: refused, naming the material and the property") {
        CHECK(refusal(R"("KHR_materials_ior": {"ior": 1e999})") != "(loaded)");
        for (const char* bad : {"\"glass\"", "[1.5]", "true"}) {
            INFO(bad);
            const std::string e = refusal(std::string(R"("KHR_materials_ior": {"ior": )") + bad + "}");
            CHECK(e.find("material 0") != std::string::npos);
            CHECK(e.find("KHR_materials_ior.ior must be a finite number") != std::string::npos);
        }
    }
}
