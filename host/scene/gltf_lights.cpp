// KHR_lights_punctual (Khronos, glTF extension registry): point, spot and directional lights
// with their node's transform, checked before they are used.
#include "scene/gltf_lights.h"

#include <algorithm>
#include <glm/gtc/constants.hpp>
#include <limits>

namespace mcrt::gltf {

namespace {

// color × intensity, checked: color has 3 components (default white), each one and intensity
// finite and ≥ 0.
glm::dvec3 checked_emission(const tinygltf::Light& light, const std::string& element,
                            const Diagnostics& diag) {
    glm::dvec3 color(1.0);
    if (!light.color.empty()) {
        if (light.color.size() != 3) diag.fail(element, "color must have 3 components");
        color = glm::dvec3(light.color[0], light.color[1], light.color[2]);
    }
    if (!is_finite(color) || std::min(color.x, std::min(color.y, color.z)) < 0.0) {
        diag.fail(element, "color must be finite and non-negative");
    }
    if (!(std::isfinite(light.intensity) && light.intensity >= 0.0)) {
        diag.fail(element, "intensity " + format_number(light.intensity) +
                               " must be finite and non-negative");
    }
    const glm::dvec3 emission = color * light.intensity;
    if (!is_finite(emission) ||
        max_component(emission) > double(std::numeric_limits<float>::max())) {
        diag.fail(element, "color × intensity is too large");
    }
    return emission;
}

// The extension's cone: 0 ≤ inner ≤ outer ≤ π/2 and outer > 0. Equal angles are a hard edge
// (the falloff's max(0.001, ·) keeps it finite), as exporters write for a spot without blend.
void check_cone(const tinygltf::SpotLight& spot, const std::string& element,
                const Diagnostics& diag) {
    const double inner = spot.innerConeAngle, outer = spot.outerConeAngle;
    const double half_pi = glm::half_pi<double>();
    if (!(std::isfinite(inner) && inner >= 0.0 && inner <= half_pi)) {
        diag.fail(element, "spot innerConeAngle " + format_number(inner) + " is not in [0, pi/2]");
    }
    if (!(std::isfinite(outer) && outer > 0.0 && outer <= half_pi)) {
        diag.fail(element, "spot outerConeAngle " + format_number(outer) + " is not in (0, pi/2]");
    }
    if (inner > outer) {
        diag.fail(element, "spot innerConeAngle " + format_number(inner) +
                               " is greater than outerConeAngle " + format_number(outer));
    }
}

}  // namespace

PunctualLight read_punctual_light(const tinygltf::Model& model, const tinygltf::Value& extension,
                                  const glm::dmat4& world, int node_index, Diagnostics& diag) {
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(node_index)];
    const std::string node_element = element_name("node", static_cast<size_t>(node_index));
    if (!extension.IsObject() || !extension.Has("light") || !extension.Get("light").IsInt()) {
        diag.fail(node_element, "KHR_lights_punctual must name a light by an integer index");
    }
    const int index = extension.Get("light").GetNumberAsInt();
    const tinygltf::Light& light = checked_at(model.lights, index, "light", node_element, diag);
    const std::string element = element_name("light", static_cast<size_t>(index));

    PunctualLight result;
    if (light.type == "point") {
        result.type = PunctualType::Point;
    } else if (light.type == "spot") {
        result.type = PunctualType::Spot;
    } else if (light.type == "directional") {
        result.type = PunctualType::Directional;
    } else {
        diag.fail(element, "unknown type \"" + light.type + "\"");
    }
    result.intensity = glm::vec3(checked_emission(light, element, diag));
    if (light.range != 0.0) {
        diag.warn_once("light range",
                       "KHR_lights_punctual range is ignored; lights fall off as 1/d^2");
    }

    // The light sits at the node's origin and points down its −Z; the node's scale does not
    // change it (KHR_lights_punctual "Adding Light Instances to Nodes").
    const glm::dvec3 position(world[3]);
    const glm::dvec3 axis = -glm::dvec3(world[2]);
    const double axis_length = glm::length(axis);
    if (!is_finite(position) || !(axis_length > 0.0) || !std::isfinite(axis_length)) {
        diag.fail(node_element, "light transform is degenerate");
    }
    result.position = glm::vec3(position);
    result.direction = glm::vec3(axis / axis_length);

    if (result.type == PunctualType::Spot) {
        check_cone(light.spot, element, diag);
        const double cos_inner = std::cos(light.spot.innerConeAngle);
        const double cos_outer = std::cos(light.spot.outerConeAngle);
        const double scale = 1.0 / std::max(0.001, cos_inner - cos_outer);
        result.cos_inner = float(cos_inner);
        result.cos_outer = float(cos_outer);
        result.spot_scale = float(scale);
        result.spot_offset = float(-cos_outer * scale);
    }
    result.name = !light.name.empty() ? light.name : !node.name.empty() ? node.name : element;
    return result;
}

}  // namespace mcrt::gltf
