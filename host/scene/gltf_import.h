// glTF 2.0 (.gltf, .glb) import into the minimal scene model.
#pragma once

#include <functional>
#include <map>
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
// The bytes of the files one load read, by the path it read them under (the scene file and its
// external buffers and images): rank 0 of an MPI render records them and sends them to the other
// ranks, which load the same scene from them without a shared file system.
using FileBundle = std::map<std::string, std::vector<unsigned char>>;

// With `record`, a copy of every file read is also kept there.
Scene load_gltf(const std::string& path, const WarningSink& warn,
                std::vector<std::string>* files_read = nullptr, FileBundle* record = nullptr);

// Loads `path` as load_gltf does, but every file (the scene's too) comes from `files`; a path
// absent from it cannot be read. The same bundle gives the same scene on every rank.
Scene load_gltf_from_bundle(const std::string& path, const FileBundle& files,
                            const WarningSink& warn);

// The same from the bytes of a .gltf or .glb file (GLB when they start with "glTF" or `name`
// ends in .glb); `name` stands for the file in messages. Nothing is read from disk: buffers and
// images must be embedded (data: URIs or the GLB binary chunk), a file name in a uri is refused.
Scene load_gltf_from_memory(const std::string& name, const std::vector<unsigned char>& bytes,
                            const WarningSink& warn);

}  // namespace mcrt
