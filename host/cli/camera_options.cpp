#include "cli/camera_options.h"

#include <cmath>
#include <glm/glm.hpp>
#include <sstream>
#include <vector>

#include "cli/validators.h"
#include "common/error.h"

namespace mcrt {
namespace {

glm::dvec3 parse_vector(const std::string& option, const std::string& text) {
    std::vector<double> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            size_t used = 0;
            double x = std::stod(item, &used);
            if (used != item.size() || !std::isfinite(x) || std::fabs(x) > 1e30)
                throw std::invalid_argument(item);
            v.push_back(x);
        } catch (const std::exception&) {
            v.clear();
            break;
        }
    }
    if (v.size() != 3)
        throw InputError(option + " " + text + ": expected X,Y,Z, three finite numbers");
    return {v[0], v[1], v[2]};
}

}  // namespace

void add_camera_options(CLI::App* cmd, CameraOptions& o, CLI::Option* excludes) {
    CLI::Option* from = cmd->add_option("--look-from", o.look_from,
                                        "camera position X,Y,Z (replaces the scene's camera)");
    CLI::Option* at = cmd->add_option("--look-at", o.look_at, "point the camera looks at, X,Y,Z");
    CLI::Option* up = cmd->add_option("--up", o.up, "camera up direction X,Y,Z (with --look-from)")
                          ->capture_default_str();
    CLI::Option* fov =
        cmd->add_option("--fov", o.fov, "vertical field of view in degrees (with --look-from)")
            ->capture_default_str()
            ->check(kFinite)
            ->check(CLI::Range(0.01f, 179.0f));
    from->needs(at);
    at->needs(from);
    up->needs(from);
    fov->needs(from);
    if (excludes) from->excludes(excludes);
}

void add_image_size_options(CLI::App* cmd, int& width, int& height) {
    cmd->add_option("--width", width, "image width")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
    cmd->add_option("--height", height, "image height")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
}

std::optional<Camera> look_at_camera(const CameraOptions& o) {
    if (o.look_from.empty()) return std::nullopt;
    const glm::dvec3 eye = parse_vector("--look-from", o.look_from);
    const glm::dvec3 at = parse_vector("--look-at", o.look_at);
    const glm::dvec3 up_hint = parse_vector("--up", o.up);
    const glm::dvec3 view = at - eye;
    const double distance = glm::length(view);
    if (!(distance > 0.0) || !std::isfinite(distance))
        throw InputError("--look-at " + o.look_at + ": the same point as --look-from " +
                         o.look_from);
    const glm::dvec3 forward = view / distance;
    const double up_length = glm::length(up_hint);
    if (!(up_length > 0.0) || !std::isfinite(up_length))
        throw InputError("--up " + o.up + ": not a direction");
    // Parallel within about 0.06 degrees: the camera's right axis would be undefined or noise.
    const glm::dvec3 side = glm::cross(forward, up_hint / up_length);
    if (!(glm::length(side) > 1e-3))
        throw InputError("--up " + o.up + ": parallel to the view from --look-from to --look-at");
    const glm::dvec3 right = glm::normalize(side);
    const glm::dvec3 up = glm::cross(right, forward);
    Camera camera;
    camera.name = "--look-from";
    camera.camera_to_world = glm::mat4(glm::dmat4(glm::dvec4(right, 0.0), glm::dvec4(up, 0.0),
                                                  glm::dvec4(-forward, 0.0), glm::dvec4(eye, 1.0)));
    camera.yfov = float(o.fov * M_PI / 180.0);
    return camera;
}

}  // namespace mcrt
