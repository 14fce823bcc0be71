// KHR_lights_punctual import (host/scene/gltf_lights.cpp): node transforms, color × intensity,
// the spot falloff of the extension's implementation notes, and hostile values, each one line.
#include <catch2/catch.hpp>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <string>
#include <vector>

#include "common/error.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"

namespace {

// A glTF file with the given lights array and one node per entry of `nodes` (each a JSON node
// object), all of them roots of the default scene.
std::string gltf_with(const std::string& lights, const std::vector<std::string>& nodes) {
    std::string node_list, roots;
    for (size_t i = 0; i < nodes.size(); ++i) {
        node_list += (i ? "," : "") + nodes[i];
        roots += (i ? "," : "") + std::to_string(i);
    }
    return R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_lights_punctual"],)"
           R"("extensions":{"KHR_lights_punctual":{"lights":[)" +
           lights +
           "]}},"
           R"("nodes":[)" +
           node_list + R"(],"scenes":[{"nodes":[)" + roots + R"(]}],"scene":0})";
}

std::string light_node(int light, const std::string& transform = "") {
    return "{" + transform + (transform.empty() ? "" : ",") +
           R"("extensions":{"KHR_lights_punctual":{"light":)" + std::to_string(light) + "}}}";
}

struct Loaded {
    mcrt::Scene scene;
    std::vector<std::string> warnings;
};

Loaded load(const std::string& json) {
    Loaded loaded;
    const std::vector<unsigned char> bytes(json.begin(), json.end());
    loaded.scene = mcrt::load_gltf_from_memory(
        "lights.gltf", bytes, [&](const std::string& w) { loaded.warnings.push_back(w); });
    return loaded;
}

// The InputError's message loading `json` throws ("" when it loads).
std::string load_error(const std::string& json) {
    try {
        load(json);
    } catch (const mcrt::InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST_CASE("A point light: position from its node, color × intensity", "[punctual]") {
    const Loaded loaded =
        load(gltf_with(R"({"type":"point","color":[1,0.5,0.25],"intensity":8,"name":"bulb"})",
                       {light_node(0, R"("translation":[1,2,3],"scale":[5,5,5])")}));
    REQUIRE(loaded.scene.punctual_lights.size() == 1);
    const mcrt::PunctualLight& light = loaded.scene.punctual_lights[0];
    CHECK(light.type == mcrt::PunctualType::Point);
    CHECK(light.name == "bulb");
    CHECK(light.position == glm::vec3(1.0f, 2.0f, 3.0f));
    CHECK(light.intensity == glm::vec3(8.0f, 4.0f, 2.0f));  // the node's scale changes nothing
    CHECK(mcrt::spot_attenuation(light, -1.0) == 1.0);
    CHECK(loaded.warnings.empty());
}

TEST_CASE("A spot light: its axis is the node's −Z, its falloff the extension's", "[punctual]") {
    // Rotated −90° about +X: −Z turns to −Y (quaternion (−sin 45°, 0, 0, cos 45°)).
    const double inner = 0.3, outer = 0.6;
    const Loaded loaded = load(
        gltf_with(R"({"type":"spot","spot":{"innerConeAngle":0.3,"outerConeAngle":0.6}})",
                  {light_node(0, R"("rotation":[-0.7071067811865476,0,0,0.7071067811865476])")}));
    REQUIRE(loaded.scene.punctual_lights.size() == 1);
    const mcrt::PunctualLight& light = loaded.scene.punctual_lights[0];
    CHECK(light.type == mcrt::PunctualType::Spot);
    CHECK(light.direction.x == Approx(0.0).margin(1e-7));
    CHECK(light.direction.y == Approx(-1.0));
    CHECK(light.direction.z == Approx(0.0).margin(1e-7));
    CHECK(light.intensity == glm::vec3(1.0f));  // defaults: white, intensity 1
    // Full inside the inner cone, zero outside the outer one, ((cos θ − cos o)/(cos i − cos o))²
    // between.
    CHECK(mcrt::spot_attenuation(light, std::cos(0.1)) == 1.0);
    CHECK(mcrt::spot_attenuation(light, std::cos(0.7)) == 0.0);
    const double mid = (std::cos(0.45) - std::cos(outer)) / (std::cos(inner) - std::cos(outer));
    CHECK(mcrt::spot_attenuation(light, std::cos(0.45)) == Approx(mid * mid).epsilon(1e-5));
}

TEST_CASE("A directional light and a shared light: one instance per node", "[punctual]") {
    const Loaded loaded =
        load(gltf_with(R"({"type":"directional","intensity":3},{"type":"point","range":10})",
                       {light_node(0), light_node(1, R"("translation":[0,1,0])"),
                        light_node(1, R"("translation":[0,2,0])")}));
    REQUIRE(loaded.scene.punctual_lights.size() == 3);
    CHECK(loaded.scene.punctual_lights[0].type == mcrt::PunctualType::Directional);
    CHECK(loaded.scene.punctual_lights[0].direction == glm::vec3(0.0f, 0.0f, -1.0f));
    CHECK(loaded.scene.punctual_lights[0].intensity == glm::vec3(3.0f));
    CHECK(loaded.scene.punctual_lights[2].position == glm::vec3(0.0f, 2.0f, 0.0f));
    CHECK(loaded.scene.punctual_lights[0].name == "light 0");
    // The range warning once, though two nodes hold the light.
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(loaded.warnings[0].find("range is ignored") != std::string::npos);
}

TEST_CASE("Lights no node holds are not imported", "[punctual]") {
    const Loaded loaded = load(gltf_with(R"({"type":"point"})", {"{}"}));
    CHECK(loaded.scene.punctual_lights.empty());
    CHECK(loaded.warnings.empty());
}

TEST_CASE("Hostile punctual lights fail with one line naming the light", "[punctual][invalid]") {
    struct Case {
        std::string light, node, expected;
    };
    const std::vector<Case> cases = {
        {R"({"type":"point","intensity":-1})", light_node(0), "light 0: intensity -1"},
        {R"({"type":"point","intensity":1e39})", light_node(0),
         "light 0: color × intensity is too large"},
        {R"({"type":"point","color":[1,-0.5,1]})", light_node(0), "light 0: color"},
        {R"({"type":"point","color":[1,1]})", light_node(0), "light 0: color must have 3"},
        {R"({"type":"area"})", light_node(0), "light 0: unknown type \"area\""},
        {R"({"type":"spot","spot":{"innerConeAngle":0.6,"outerConeAngle":0.3}})", light_node(0),
         "light 0: spot innerConeAngle 0.6 is greater than outerConeAngle 0.3"},
        {R"({"type":"spot","spot":{"outerConeAngle":2}})", light_node(0),
         "light 0: spot outerConeAngle 2 is not in (0, pi/2]"},
        {R"({"type":"spot","spot":{"innerConeAngle":-0.1}})", light_node(0),
         "light 0: spot innerConeAngle -0.1"},
        {R"({"type":"spot","spot":{"outerConeAngle":0}})", light_node(0),
         "light 0: spot outerConeAngle 0"},
        {R"({"type":"point"})", light_node(3), "node 0: light 3 out of range"},
        {R"({"type":"point"})", light_node(-1), "node 0: light -1 out of range"},
        {R"({"type":"point"})", R"({"extensions":{"KHR_lights_punctual":{"light":"0"}}})",
         "node 0: KHR_lights_punctual must name a light"},
        {R"({"type":"point"})", light_node(0, R"("scale":[1,1,0])"),
         "node 0: light transform is degenerate"},
    };
    for (const Case& c : cases) {
        INFO(c.light << " " << c.node);
        const std::string message = load_error(gltf_with(c.light, {c.node}));
        CHECK(message.find("lights.gltf: " + c.expected) == 0);
        CHECK(message.find('\n') == std::string::npos);
    }
}

TEST_CASE("punctual_power: 4πI, 2πI(1 − (cos i + cos o)/2) and πr²E", "[punctual]") {
    const Loaded loaded = load(gltf_with(
        R"({"type":"point","color":[0,1,0],"intensity":2},)"
        R"({"type":"spot","intensity":3,"spot":{"innerConeAngle":0.2,"outerConeAngle":0.4}},)"
        R"({"type":"directional","intensity":5})",
        {light_node(0), light_node(1), light_node(2)}));
    REQUIRE(loaded.scene.punctual_lights.size() == 3);
    const double pi = glm::pi<double>();
    CHECK(mcrt::punctual_power(loaded.scene.punctual_lights[0], 1.0) ==
          Approx(4.0 * pi * 0.7152 * 2.0));
    CHECK(mcrt::punctual_power(loaded.scene.punctual_lights[1], 1.0) ==
          Approx(2.0 * pi * 3.0 * (1.0 - 0.5 * (std::cos(0.2) + std::cos(0.4)))).epsilon(1e-6));
    CHECK(mcrt::punctual_power(loaded.scene.punctual_lights[2], 2.0) == Approx(pi * 4.0 * 5.0));
}
