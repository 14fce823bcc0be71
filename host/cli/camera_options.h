// --look-from, --look-at, --up, --fov: a camera given on the command line (DESIGN.md "Camera
// contract"), for `render` and `bench`, in place of the scene's; --width, --height: its image.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "scene/scene.h"

namespace mcrt {

struct CameraOptions {
    std::string look_from, look_at;  // X,Y,Z; both or neither
    std::string up = "0,1,0";        // X,Y,Z, not parallel to the view
    float fov = 45.0f;               // vertical field of view in degrees, (0, 180)
};

// Adds the four options to `cmd`; --look-from and --look-at need each other, --up and --fov
// need them; `excludes`, if any (--camera), cannot be given with them.
void add_camera_options(CLI::App* cmd, CameraOptions& o, CLI::Option* excludes = nullptr);

// Adds --width and --height, the image's size in pixels (1 to 16384 each), for `render` and
// `bench`.
void add_image_size_options(CLI::App* cmd, int& width, int& height);

// The camera the options give, or none when --look-from is not given. Throws InputError naming
// the option for a vector that is not three finite numbers, --look-from equal to --look-at, or
// --up parallel to the view.
std::optional<Camera> look_at_camera(const CameraOptions& o);

}  // namespace mcrt
