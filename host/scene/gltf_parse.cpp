// One parse of glTF bytes for every origin (disk, bundle, memory), with one set of tinygltf file
// callbacks, after the guards tinygltf lacks (JSON nesting, property types) have seen the text.
#include "scene/gltf_parse.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>

#include "common/error.h"
#include "common/regular_file.h"
#include "scene/gltf_limits.h"
#include "scene/gltf_types.h"
#include "scene/gltf_uris.h"
#include "scene/json_guard.h"

namespace mcrt::gltf {

namespace {

// Extensions whose every effect on mcrt's scene model is implemented: a file may require them
// ("Specifying Extensions": a loader must refuse a file requiring any other).
const std::set<std::string> kSupportedRequiredExtensions = {
    "KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_mesh_quantization",
    "KHR_texture_transform"};

bool has_glb_extension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension == ".glb";
}

// tinygltf's image loader: the encoded bytes of a uri (its file or data URI) are kept in
// Image::image for gltf_images.cpp, which decodes only the images materials use. A bufferView
// image's bytes stay in their buffer: tinygltf hands them over without checking that the view
// lies inside the buffer, so they are read only once gltf_images.cpp has checked it.
bool keep_encoded_image(tinygltf::Image* image, const int index, std::string* error, std::string*,
                        int, int, const unsigned char* bytes, int size, void*) {
    if (size < 0) {  // tinygltf passes the size as an int
        if (error) *error += "image " + std::to_string(index) + ": larger than 2 GiB";
        return false;
    }
    if (image->bufferView == -1 && size > 0) {
        image->image.assign(bytes, bytes + size);
        image->as_is = true;
    }
    return true;
}

// tinygltf's messages end in newlines and may hold several lines: make them one line.
std::string one_line(const std::string& text) {
    std::istringstream lines(text);
    std::string line, joined;
    while (std::getline(lines, line)) {
        if (line.empty()) continue;
        joined += (joined.empty() ? "" : "; ") + line;
    }
    return joined.empty() ? "invalid glTF file" : joined;
}

// Where one load reads files from, and what tinygltf's file callbacks (their user_data) keep
// while it parses. From the disk only the regular files that the uris name are read, relative to
// the scene's directory (or reached from it by `../`) or absolute; tinygltf's fallback to the
// current directory is cut, and every refusal (FIFO, directory, device, missing) is kept to name
// the real cause. From memory no file exists.
struct FileAccess {
    enum class Origin { Disk, Bundle, Memory };
    Origin origin = Origin::Disk;
    FileBundle* record = nullptr;                    // Disk: keeps a copy of what is read
    const FileBundle* bundle = nullptr;              // Bundle: read from here instead of the disk
    std::string base_prefix;                         // the scene's directory and "/"
    std::map<std::string, gltf::UriTarget> targets;  // by the path tinygltf asks for
    uint64_t image_bytes = 0;                        // image files read so far
    std::vector<std::string> files_read;             // external files, in the order read
    std::string first_refusal;  // refusals of optional files (images) tinygltf drops
    std::string size_refusal;   // a file of the wrong size, named by its element
};

// One file, from the bundle when there is one, else from the disk (recorded when asked).
bool read_file(FileAccess& access, const std::string& path, std::vector<unsigned char>& out,
               std::string& why) {
    if (access.origin == FileAccess::Origin::Bundle) {
        auto it = access.bundle->find(path);
        if (it == access.bundle->end()) {
            why = "not among the files of the bundle";
            return false;
        }
        out = it->second;
        return true;
    }
    FileSizeLimits limits;
    limits.max_bytes = kMaxFileBytes;
    if (!read_regular_file(path, out, why, limits)) return false;
    if (access.record) (*access.record)[path] = out;
    return true;
}

// What a uri names: a buffer is read up to its byteLength ("Buffers": the resource MUST be at
// least byteLength long, so a longer file is valid) and refused when shorter; an image file, whose
// size nothing declares, within kMaxImageFileBytes. Both before any byte is read.
bool read_target(FileAccess& access, const gltf::UriTarget& target, std::vector<unsigned char>& out,
                 std::string& why) {
    if (access.origin == FileAccess::Origin::Bundle)
        return read_file(access, target.path, out, why);
    FileSizeLimits limits;
    if (target.buffer) {
        if (target.byte_length > kMaxFileBytes) {
            why = "byteLength " + std::to_string(target.byte_length) + " is more than 4 GiB";
            access.size_refusal = target.element + ": " + why;
            return false;
        }
        limits.min_bytes = limits.read_bytes = target.byte_length;
    } else {
        limits.max_bytes =
            std::min<uint64_t>(kMaxImageFileBytes, kMaxImageFilesBytes - access.image_bytes);
    }
    if (!read_regular_file(target.path, out, why, limits)) {
        const bool size = why.compare(0, 6, "holds ") == 0;
        if (size && target.buffer) why += " by its byteLength";
        if (size && !target.buffer && access.image_bytes > 0)
            why += " (of 4 GiB for all image files, " + std::to_string(access.image_bytes) +
                   " bytes read before)";
        if (size) access.size_refusal = target.element + ": uri '" + target.uri + "': " + why;
        return false;
    }
    if (!target.buffer) access.image_bytes += out.size();
    if (access.record) (*access.record)[target.path] = out;
    return true;
}

// tinygltf::FsCallbacks, the same for every origin.
bool file_exists(const std::string& path, void* user) {
    // Claim the first candidate exists so the reader names why it cannot be read; from memory
    // none does, so a uri naming a file fails with tinygltf's "File not found".
    const auto* access = static_cast<const FileAccess*>(user);
    if (access->origin == FileAccess::Origin::Memory) return false;
    return path.compare(0, access->base_prefix.size(), access->base_prefix) == 0 ||
           access->targets.count(path);
}
bool file_read(std::vector<unsigned char>* out, std::string* error, const std::string& path,
               void* user) {
    auto* access = static_cast<FileAccess*>(user);
    if (access->origin == FileAccess::Origin::Memory) {
        if (error) *error = path + ": external files are not read when loading from memory";
        return false;
    }
    std::string why;
    const auto target = access->targets.find(path);
    const std::string& read_path = target != access->targets.end() ? target->second.path : path;
    const bool ok = target != access->targets.end()
                        ? read_target(*access, target->second, *out, why)
                        : read_file(*access, path, *out, why);
    if (!ok) {
        if (error) *error = why;
        if (access->first_refusal.empty()) access->first_refusal = read_path + ": " + why;
        return false;
    }
    access->files_read.push_back(read_path);
    return true;
}
// tinygltf joins every uri to the scene's directory: an absolute path comes back as itself.
std::string expand_path(const std::string& path, void* user) {
    const auto* access = static_cast<const FileAccess*>(user);
    const std::string& prefix = access->base_prefix;
    if (!prefix.empty() && path.size() > prefix.size() && path[prefix.size()] == '/' &&
        path.compare(0, prefix.size(), prefix) == 0)
        return path.substr(prefix.size());
    return path;
}
bool no_file_write(std::string* error, const std::string&, const std::vector<unsigned char>&,
                   void*) {
    if (error) *error = "not writable";
    return false;
}

// Parses the glTF bytes of `name` (GLB when they start with "glTF" or `name` ends in .glb); the
// uris they name are resolved against `base_dir` and read through `access`. tinygltf's false
// return, an exception it throws, or a file it could not read becomes InputError naming `name`.
tinygltf::Model parse_gltf(const std::string& name, const std::vector<unsigned char>& bytes,
                           const std::string& base_dir, FileAccess& access) {
    if (bytes.empty()) throw InputError(name + ": the file is empty");
    const bool binary =
        (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) || has_glb_extension(name);
    check_json_nesting(name, bytes.data(), bytes.size(), binary);
    const char* json = reinterpret_cast<const char*>(bytes.data());
    size_t json_size = bytes.size();
    const bool has_json = !binary || glb_json_chunk(bytes.data(), bytes.size(), &json, &json_size);
    if (has_json)
        check_gltf_property_types(name, reinterpret_cast<const unsigned char*>(json), json_size);

    access.base_prefix = base_dir.empty() || base_dir.back() == '/' ? base_dir : base_dir + "/";
    if (has_json) access.targets = gltf::scan_uris(name, json, json_size, base_dir);
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keep_encoded_image, nullptr);
    loader.SetFsCallbacks(
        tinygltf::FsCallbacks{file_exists, expand_path, file_read, no_file_write, &access});
    const auto length = static_cast<unsigned int>(bytes.size());
    tinygltf::Model model;
    std::string error, warning;  // tinygltf's warnings concern images and unknown data
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromMemory(&model, &error, &warning, bytes.data(), length,
                                                  base_dir)
                    : loader.LoadASCIIFromString(&model, &error, &warning,
                                                 reinterpret_cast<const char*>(bytes.data()),
                                                 length, base_dir);
    } catch (const std::bad_alloc&) {
        throw;  // not the file's fault: out of host memory (run_cli names it)
    } catch (const std::exception& e) {
        throw InputError(name + ": " + e.what());
    }
    if (!access.size_refusal.empty()) throw InputError(name + ": " + access.size_refusal);
    // An empty image file fails with a warning alone as its reason.
    if (!ok) throw InputError(name + ": " + one_line(error.empty() ? warning : error));
    if (!access.first_refusal.empty()) throw InputError(name + ": " + access.first_refusal);
    return model;
}

// The scene file `path` read through `access`, parsed with its uris resolved in its directory.
tinygltf::Model read_and_parse(const std::string& path, std::vector<std::string>* files_read,
                               FileAccess& access) {
    std::vector<unsigned char> bytes;
    std::string why;
    if (!read_file(access, path, bytes, why)) throw InputError(path + ": cannot open: " + why);
    std::string base_dir = std::filesystem::path(path).parent_path().string();
    if (base_dir.empty()) base_dir = ".";
    tinygltf::Model model = parse_gltf(path, bytes, base_dir, access);
    if (files_read) {
        files_read->push_back(path);
        files_read->insert(files_read->end(), access.files_read.begin(), access.files_read.end());
    }
    return model;
}

}  // namespace

tinygltf::Model read_gltf_file(const std::string& path, std::vector<std::string>* files_read,
                               FileBundle* record) {
    FileAccess access;
    access.origin = FileAccess::Origin::Disk;
    access.record = record;
    return read_and_parse(path, files_read, access);
}

tinygltf::Model read_gltf_bundle(const std::string& path, const FileBundle& files) {
    FileAccess access;
    access.origin = FileAccess::Origin::Bundle;
    access.bundle = &files;
    return read_and_parse(path, nullptr, access);
}

tinygltf::Model read_gltf_memory(const std::string& name, const std::vector<unsigned char>& bytes) {
    if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
        throw InputError(name + ": larger than 4 GiB");  // tinygltf takes an unsigned length
    }
    FileAccess access;
    access.origin = FileAccess::Origin::Memory;
    return parse_gltf(name, bytes, "", access);
}

void check_asset(const tinygltf::Model& model, const Diagnostics& diag) {
    const std::string& version = model.asset.version;
    if (version.size() < 3 || version.compare(0, 2, "2.") != 0 ||
        version.find_first_not_of("0123456789", 2) != std::string::npos) {
        diag.fail("asset.version \"" + version + "\" is not 2.x (glTF 2.0 is read)");
    }
    const std::string& min_version = model.asset.minVersion;
    if (!min_version.empty() && min_version != "2.0") {
        diag.fail("asset.minVersion \"" + min_version + "\" is newer than the 2.0 mcrt reads");
    }
    for (const std::string& extension : model.extensionsRequired) {
        if (!kSupportedRequiredExtensions.count(extension)) {
            diag.fail("extensionsRequired names " + extension + ", which mcrt does not implement");
        }
    }
}

}  // namespace mcrt::gltf
