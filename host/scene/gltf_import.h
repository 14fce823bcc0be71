// glTF 2.0 (.gltf, .glb) import into the minimal scene model.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace mcrt {

// Called once per kind of unsupported content (textures, points, orthographic cameras, ...).
using WarningSink = std::function<void(const std::string&)>;

// Loads the default scene of a glTF file. Throws InputError (naming the file and the glTF
// element) for unreadable or invalid files: out-of-range indices, node cycles, accessors that
// overrun their buffer views, non-finite positions, ...
// With `files_read`, the paths of the scene file and of every external file read for it are
// appended (outputs must not replace them). Only regular files are read; a FIFO, directory or
// device, as the scene or a uri, is refused naming what it is.
Scene load_gltf(const std::string& path, const WarningSink& warn,
                std::vector<std::string>* files_read = nullptr);

// The same from the bytes of a .gltf or .glb file (GLB when they start with "glTF" or `name`
// ends in .glb); `name` stands for the file in messages. Nothing is read from disk: buffers and
// images must be embedded (data: URIs or the GLB binary chunk), a file name in a uri is refused.
Scene load_gltf_from_memory(const std::string& name, const std::vector<unsigned char>& bytes,
                            const WarningSink& warn);

}  // namespace mcrt
