// glTF cameras ("Cameras"): perspective cameras as mcrt's Camera, their frame the node's
// transform without its scale; orthographic cameras are warned about and ignored.
#include "scene/gltf_cameras.h"

#include <glm/gtc/constants.hpp>

namespace mcrt::gltf {

namespace {

// The camera's rigid frame: scale and shear removed, the view direction (−Z) kept exactly, up as
// close to the node's +Y as possible, and right = up × back so the frame stays right-handed even
// under a mirroring node transform. A degenerate frame returns false.
bool rigid_frame(const glm::dmat4& world, glm::dmat4& frame) {
    const glm::dvec3 y(world[1]);
    const glm::dvec3 back = glm::normalize(glm::dvec3(world[2]));
    const glm::dvec3 right = glm::normalize(glm::cross(y, back));
    const glm::dvec3 up = glm::cross(back, right);
    const glm::dvec3 eye(world[3]);
    frame = glm::dmat4(glm::dvec4(right, 0.0), glm::dvec4(up, 0.0), glm::dvec4(back, 0.0),
                       glm::dvec4(eye, 1.0));
    return is_finite(right) && is_finite(up) && is_finite(back) && is_finite(eye);
}

}  // namespace

std::optional<Camera> read_camera(const tinygltf::Model& model, int camera_index,
                                  const glm::dmat4& world, int node_index, Diagnostics& diag) {
    const std::string node_element = element_name("node", static_cast<size_t>(node_index));
    const tinygltf::Camera& camera =
        checked_at(model.cameras, camera_index, "camera", node_element, diag);
    const std::string element = element_name("camera", static_cast<size_t>(camera_index));
    if (camera.type == "orthographic") {
        diag.warn_once("orthographic", "orthographic cameras are not supported; ignored");
        return std::nullopt;
    }
    if (camera.type != "perspective") diag.fail(element, "unknown type \"" + camera.type + "\"");
    const double yfov = camera.perspective.yfov;
    if (!(yfov > 0.0 && yfov < glm::pi<double>())) {
        diag.fail(element, "yfov " + format_number(yfov) + " is not in (0, pi)");
    }
    glm::dmat4 frame;
    if (!rigid_frame(world, frame)) diag.fail(node_element, "camera transform is degenerate");

    Camera result;
    result.name = !camera.name.empty() ? camera.name
                  : !model.nodes[static_cast<size_t>(node_index)].name.empty()
                      ? model.nodes[static_cast<size_t>(node_index)].name
                      : element;
    result.camera_to_world = glm::mat4(frame);
    result.yfov = static_cast<float>(yfov);
    return result;
}

}  // namespace mcrt::gltf
