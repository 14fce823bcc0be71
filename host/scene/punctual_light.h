// glTF's KHR_lights_punctual lights as mcrt's scene holds them: points, spots and directional
// lights, in world space, with their emission in mcrt's units (DESIGN.md "Punctual lights").
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>

namespace mcrt {

enum class PunctualType : uint8_t { Point, Spot, Directional };

// One light of one node. A point or spot light radiates `intensity` (color × intensity, radiant
// intensity: the units of mcrt's emission × m², so candela goes with nits) from `position`; a
// directional light delivers `intensity` as irradiance on a surface facing it (lux with nits).
struct PunctualLight {
    std::string name;  // the light's, else the node's, else "light N"
    PunctualType type = PunctualType::Point;
    glm::vec3 position{0.0f};                // world; unused for a directional light
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // world, unit: where the light points (node's −Z)
    glm::vec3 intensity{1.0f};               // color × intensity, every component ≥ 0 and finite
    // Spot: attenuation = clamp(cos θ · spot_scale + spot_offset, 0, 1)², θ from `direction`,
    // scale = 1/max(0.001, cos inner − cos outer), offset = −cos outer · scale (the extension's
    // implementation notes). A point or directional light has scale 0, offset 1 (no falloff).
    float cos_inner = 1.0f, cos_outer = -1.0f;
    float spot_scale = 0.0f, spot_offset = 1.0f;
};

// The spot falloff above, in double: the host twin of the kernel's.
inline double spot_attenuation(const PunctualLight& light, double cos_theta) {
    double t = cos_theta * double(light.spot_scale) + double(light.spot_offset);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return t * t;
}

// The power a light selection weighs a punctual light by, from the luminance of its intensity
// (Rec. 709): 4πI for a point light, 2πI(1 − (cos inner + cos outer)/2) for a spot (pbrt-v4's
// SpotLight::Phi), πr²E for a directional light over the disk of the scene's bounding sphere of
// radius `bounding_radius` (pbrt-v4's DistantLight::Phi).
inline double punctual_power(const PunctualLight& light, double bounding_radius) {
    const double pi = 3.14159265358979323846;
    const double y =
        0.2126 * light.intensity.r + 0.7152 * light.intensity.g + 0.0722 * light.intensity.b;
    switch (light.type) {
        case PunctualType::Point:
            return 4.0 * pi * y;
        case PunctualType::Spot:
            return 2.0 * pi * y * (1.0 - 0.5 * (double(light.cos_inner) + double(light.cos_outer)));
        case PunctualType::Directional:
            return pi * bounding_radius * bounding_radius * y;
    }
    return 0.0;
}

}  // namespace mcrt
