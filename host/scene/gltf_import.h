// glTF 2.0 (.gltf, .glb) import into the minimal scene model.
#pragma once

#include <functional>
#include <string>

#include "scene/scene.h"

namespace mcrt {

// Called once per kind of unsupported content (textures, points, orthographic cameras, ...).
using WarningSink = std::function<void(const std::string&)>;

// Loads the default scene of a glTF file. Throws InputError (naming the file and the glTF
// element) for unreadable or invalid files: out-of-range indices, node cycles, accessors that
// overrun their buffer views, non-finite positions, ...
Scene load_gltf(const std::string& path, const WarningSink& warn);

}  // namespace mcrt
