// Reading a glTF file with tinygltf: the file, its GLB container and the buffers and images it
// names, from the disk, a FileBundle or memory, through one parse; and the checks of its asset.
#pragma once

#include <tiny_gltf.h>

#include <string>
#include <vector>

#include "scene/gltf_diagnostics.h"
#include "scene/gltf_import.h"

namespace mcrt::gltf {

// Reads and parses the .gltf or .glb file `path` and the files it names, from the disk: only
// regular files below its directory (or reached from it by `../`). With `files_read`, `path` and
// every external file read are appended; with `record`, a copy of each is kept there.
tinygltf::Model read_gltf_file(const std::string& path, std::vector<std::string>* files_read,
                               FileBundle* record);

// The same with every file, the scene's too, from `files`.
tinygltf::Model read_gltf_bundle(const std::string& path, const FileBundle& files);

// Parses the bytes of a .gltf or .glb file; nothing is read from disk, so a uri naming a file
// fails. `name` stands for the file in messages.
tinygltf::Model read_gltf_memory(const std::string& name, const std::vector<unsigned char>& bytes);

// "Asset": version 2.x, minVersion at most 2.0; "Specifying Extensions": every extension in
// extensionsRequired must be supported.
void check_asset(const tinygltf::Model& model, const Diagnostics& diag);

}  // namespace mcrt::gltf
