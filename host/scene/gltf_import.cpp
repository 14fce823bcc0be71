// glTF 2.0 import: the default scene's triangles, metallic-roughness materials and perspective cameras.
//
// tinygltf parses the file; it accepts out-of-range indices, node cycles and accessors that
// overrun their data, so everything this file reads is validated here first. Quoted section
// names refer to the glTF 2.0 specification (Khronos, 2021).
#include "scene/gltf_import.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <array>
#include <tuple>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>
#include <sstream>

#include "common/error.h"
#include "common/regular_file.h"
#include "common/value_limits.h"
#include "scene/gltf_types.h"
#include "scene/json_guard.h"

namespace mcrt {

namespace {

// Sanity limits: beyond them a file is treated as invalid rather than exhausting memory.
constexpr double kMaxCoordinate = 1e30;                 // any position component
constexpr size_t kMaxTriangles = size_t(1) << 26;       // after instancing
constexpr size_t kMaxNodeInstances = size_t(1) << 24;   // shared subtrees multiply
constexpr size_t kMaxZeroBasedCount = size_t(1) << 24;  // sparse accessor without data
constexpr size_t kMaxFileBytes = size_t(4) << 30;       // the scene file and each buffer
// Beyond this magnitude float traversal may lose triangles: a floor quad of half-size S seen by
// the bench camera renders for S ≤ 2e12, partly at 4e12, not at 7e12 (ROBUSTNESS.md "Silently
// wrong input"); the bound keeps a factor 200 of margin. Such scenes load with one warning.
constexpr double kWarnCoordinate = 1e10;
// Extensions whose every effect on mcrt's scene model is implemented (or, for texture
// transforms, void since textures are ignored): a file may require them ("Specifying
// Extensions": a loader must refuse a file requiring any other).
const std::set<std::string> kSupportedRequiredExtensions = {
    "KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_mesh_quantization",
    "KHR_texture_transform"};

// ---------------------------------------------------------------------------------------------
// Diagnostics: errors name the file and the glTF element; warnings come once per kind.
// ---------------------------------------------------------------------------------------------

class Diagnostics {
  public:
    Diagnostics(std::string path, const WarningSink& sink) : path_(std::move(path)), sink_(sink) {}

    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw InputError(path_ + ": " + element + ": " + what);
    }
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }

    void warn_once(const std::string& kind, const std::string& message) {
        if (!warned_.insert(kind).second) return;
        if (sink_) sink_(path_ + ": " + message);
    }

  private:
    std::string path_;
    const WarningSink& sink_;
    std::set<std::string> warned_;
};

// A number as a person would write it (std::to_string prints 0.000000 for 1e-9).
std::string format_number(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

std::string element_name(const char* kind, size_t index) {
    return std::string(kind) + " " + std::to_string(index);
}

// The element `index` of `items`, or an error "<referrer>: <what> <index> out of range".
template <typename T>
const T& checked_at(const std::vector<T>& items, long long index, const std::string& what,
                    const std::string& referrer, const Diagnostics& diag) {
    if (index < 0 || static_cast<unsigned long long>(index) >= items.size()) {
        diag.fail(referrer, what + " " + std::to_string(index) + " out of range");
    }
    return items[static_cast<size_t>(index)];
}

bool all_finite(const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

double max_component(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

bool is_finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// ---------------------------------------------------------------------------------------------
// Reading the file
// ---------------------------------------------------------------------------------------------

bool has_glb_extension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension == ".glb";
}

// Textures are not used (DESIGN.md "Radiometric contract"): keep the image bytes undecoded.
bool skip_image_decoding(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                         const unsigned char*, int, void*) {
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

// A loader that keeps image bytes undecoded.
tinygltf::TinyGLTF make_loader() {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image_decoding, nullptr);
    return loader;
}

// Runs one tinygltf load call; a false return or an exception becomes InputError naming `name`.
template <typename LoadCall>
tinygltf::Model parse_model(const std::string& name, LoadCall load) {
    tinygltf::Model model;
    std::string error, warning;  // tinygltf's warnings concern images and unknown data: dropped
    bool ok = false;
    try {
        ok = load(&model, &error, &warning);
    } catch (const std::exception& e) {
        throw InputError(name + ": " + e.what());
    }
    if (!ok) throw InputError(name + ": " + one_line(error));
    return model;
}

// File-system callbacks for loading from disk: only regular files below the scene's directory
// (or reached from it by `../`) are read; tinygltf's fallback to the current directory is cut,
// and every refusal (FIFO, directory, device, missing) is kept to name the real cause.
struct DiskAccess {
    std::string base_prefix;            // the scene's directory and "/"
    std::vector<std::string> files_read;
    std::string first_refusal;          // refusals of optional files (images) tinygltf drops
    FileBundle* record = nullptr;       // keeps a copy of what is read (load_gltf's `record`)
    const FileBundle* source = nullptr; // read from here instead of the disk (from a bundle)
};

// One file, from the bundle when there is one, else from the disk (recorded when asked).
bool read_scene_file(DiskAccess& access, const std::string& path, std::vector<unsigned char>& out,
                     std::string& why) {
    if (access.source) {
        auto it = access.source->find(path);
        if (it == access.source->end()) {
            why = "not among the files of the bundle";
            return false;
        }
        out = it->second;
        return true;
    }
    if (!read_regular_file(path, out, why, kMaxFileBytes)) return false;
    if (access.record) (*access.record)[path] = out;
    return true;
}

bool disk_file_exists(const std::string& path, void* user) {
    // Claim the first candidate exists so the reader names why it cannot be read.
    const auto* access = static_cast<const DiskAccess*>(user);
    return path.compare(0, access->base_prefix.size(), access->base_prefix) == 0;
}
bool disk_file_read(std::vector<unsigned char>* out, std::string* error, const std::string& path,
                    void* user) {
    auto* access = static_cast<DiskAccess*>(user);
    std::string why;
    if (!read_scene_file(*access, path, *out, why)) {
        if (error) *error = why;
        if (access->first_refusal.empty()) access->first_refusal = path + ": " + why;
        return false;
    }
    access->files_read.push_back(path);
    return true;
}
std::string disk_path_unchanged(const std::string& path, void*) { return path; }
bool disk_no_write(std::string* error, const std::string&, const std::vector<unsigned char>&,
                   void*) {
    if (error) *error = "not writable";
    return false;
}

tinygltf::Model read_model(const std::string& path, std::vector<std::string>* files_read,
                           DiskAccess access = {}) {
    std::vector<unsigned char> bytes;
    std::string why;
    if (!read_scene_file(access, path, bytes, why)) {
        throw InputError(path + ": cannot open: " + why);
    }
    if (bytes.empty()) throw InputError(path + ": the file is empty");
    const bool binary = (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) ||
                        has_glb_extension(path);
    check_json_nesting(path, bytes.data(), bytes.size(), binary);
    {
        const char* json = reinterpret_cast<const char*>(bytes.data());
        size_t json_size = bytes.size();
        if (!binary || glb_json_chunk(bytes.data(), bytes.size(), &json, &json_size))
            check_gltf_property_types(path, reinterpret_cast<const unsigned char*>(json), json_size);
    }

    std::string base_dir = std::filesystem::path(path).parent_path().string();
    if (base_dir.empty()) base_dir = ".";
    access.base_prefix = base_dir + "/";
    tinygltf::TinyGLTF loader = make_loader();
    loader.SetFsCallbacks(tinygltf::FsCallbacks{disk_file_exists, disk_path_unchanged,
                                                disk_file_read, disk_no_write, &access});
    const auto length = static_cast<unsigned int>(bytes.size());
    tinygltf::Model model =
        parse_model(path, [&](tinygltf::Model* m, std::string* error, std::string* warning) {
            return binary ? loader.LoadBinaryFromMemory(m, error, warning, bytes.data(), length,
                                                        base_dir)
                          : loader.LoadASCIIFromString(
                                m, error, warning, reinterpret_cast<const char*>(bytes.data()),
                                length, base_dir);
        });
    if (!access.first_refusal.empty()) throw InputError(path + ": " + access.first_refusal);
    if (files_read) {
        files_read->push_back(path);
        files_read->insert(files_read->end(), access.files_read.begin(), access.files_read.end());
    }
    return model;
}

// File-system callbacks for loading from memory: no file exists, so a uri naming a file fails
// with tinygltf's "File not found" and nothing is read from disk.
bool no_file_exists(const std::string&, void*) { return false; }
std::string path_unchanged(const std::string& path, void*) { return path; }
bool no_file_read(std::vector<unsigned char>*, std::string* error, const std::string& path, void*) {
    if (error) *error = path + ": external files are not read when loading from memory";
    return false;
}
bool no_file_write(std::string* error, const std::string&, const std::vector<unsigned char>&,
                   void*) {
    if (error) *error = "not writable";
    return false;
}

tinygltf::Model read_model_from_memory(const std::string& name,
                                       const std::vector<unsigned char>& bytes) {
    if (bytes.empty()) throw InputError(name + ": the file is empty");
    if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
        throw InputError(name + ": larger than 4 GiB");  // tinygltf takes an unsigned length
    }
    tinygltf::TinyGLTF loader = make_loader();
    loader.SetFsCallbacks(tinygltf::FsCallbacks{no_file_exists, path_unchanged, no_file_read,
                                                no_file_write, nullptr});
    const auto length = static_cast<unsigned int>(bytes.size());
    const bool binary =
        (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) || has_glb_extension(name);
    check_json_nesting(name, bytes.data(), bytes.size(), binary);
    const char* json = reinterpret_cast<const char*>(bytes.data());
    size_t json_size = bytes.size();
    if (!binary || glb_json_chunk(bytes.data(), bytes.size(), &json, &json_size))
        check_gltf_property_types(name, reinterpret_cast<const unsigned char*>(json), json_size);
    tinygltf::Model model =
        parse_model(name, [&](tinygltf::Model* m, std::string* error, std::string* warning) {
            return binary ? loader.LoadBinaryFromMemory(m, error, warning, bytes.data(), length, "")
                          : loader.LoadASCIIFromString(m, error, warning,
                                                       reinterpret_cast<const char*>(bytes.data()),
                                                       length, "");
        });
    return model;
}

// ---------------------------------------------------------------------------------------------
// Accessors ("Accessors", "Accessor Data Types", "Sparse Accessors", "Data Alignment")
// ---------------------------------------------------------------------------------------------

size_t component_size(int component_type) {
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return 4;
        default:
            return 0;  // INT and DOUBLE are not glTF 2.0 component types
    }
}

size_t components_per_element(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return 1;
        case TINYGLTF_TYPE_VEC2:
            return 2;
        case TINYGLTF_TYPE_VEC3:
            return 3;
        case TINYGLTF_TYPE_VEC4:
            return 4;
        case TINYGLTF_TYPE_MAT2:
            return 4;
        case TINYGLTF_TYPE_MAT3:
            return 9;
        case TINYGLTF_TYPE_MAT4:
            return 16;
        default:
            return 0;
    }
}

// One component as a double; normalized integers map to [0, 1] or [-1, 1] as the spec's
// "Animations" table of normalized integer decoding says (e.g. max(c / 127, -1)).
double read_component(const unsigned char* p, int component_type, bool normalized) {
    auto load = [p](auto value) {
        std::memcpy(&value, p, sizeof value);
        return value;
    };
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            double c = load(int8_t{});
            return normalized ? std::max(c / 127.0, -1.0) : c;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            double c = load(uint8_t{});
            return normalized ? c / 255.0 : c;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            double c = load(int16_t{});
            return normalized ? std::max(c / 32767.0, -1.0) : c;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            double c = load(uint16_t{});
            return normalized ? c / 65535.0 : c;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            double c = load(uint32_t{});
            return normalized ? c / 4294967295.0 : c;
        }
        default:
            return load(float{});
    }
}

// Bytes [offset, offset + size) exist: checks without overflowing size_t.
bool range_fits(size_t offset, size_t size, size_t length) {
    return offset <= length && size <= length - offset;
}

// A strided run of `count` elements of `element_size` bytes inside one buffer view.
struct ElementRun {
    const unsigned char* data = nullptr;
    size_t stride = 0;
};

// Validates buffer view `view_index` and the run of elements read from it at `byte_offset`:
// byte_offset + stride·(count − 1) + element_size ≤ byteLength ("Data Alignment"), and the
// view inside its buffer. `packed` runs (sparse indices and values) ignore byteStride.
ElementRun locate_elements(const tinygltf::Model& model, long long view_index, size_t byte_offset,
                           size_t count, size_t element_size, bool packed,
                           const std::string& element, const Diagnostics& diag) {
    const tinygltf::BufferView& view =
        checked_at(model.bufferViews, view_index, "bufferView", element, diag);
    const std::string view_element = element_name("bufferView", static_cast<size_t>(view_index));
    const tinygltf::Buffer& buffer =
        checked_at(model.buffers, view.buffer, "buffer", view_element, diag);
    if (!range_fits(view.byteOffset, view.byteLength, buffer.data.size())) {
        diag.fail(view_element, "bytes " + std::to_string(view.byteOffset) + " + " +
                                    std::to_string(view.byteLength) + " overrun buffer " +
                                    std::to_string(view.buffer) + " (" +
                                    std::to_string(buffer.data.size()) + " bytes)");
    }
    const size_t stride = (packed || view.byteStride == 0) ? element_size : view.byteStride;
    if (stride < element_size) {
        diag.fail(view_element, "byteStride " + std::to_string(stride) +
                                    " is smaller than an element (" + std::to_string(element_size) +
                                    " bytes)");
    }
    if (count > 0) {
        const bool fits =
            (count - 1) <= (std::numeric_limits<size_t>::max() - element_size) / stride &&
            range_fits(byte_offset, (count - 1) * stride + element_size, view.byteLength);
        if (!fits) {
            diag.fail(element, std::to_string(count) + " elements from byte " +
                                   std::to_string(byte_offset) + " overrun " + view_element + " (" +
                                   std::to_string(view.byteLength) + " bytes)");
        }
    }
    return ElementRun{buffer.data.data() + view.byteOffset + byte_offset, stride};
}

// Applies the sparse substitution ("Sparse Accessors"): values[indices[i]] = sparse values[i].
void apply_sparse(const tinygltf::Model& model, const tinygltf::Accessor& accessor,
                  size_t components, std::vector<double>& values, const std::string& element,
                  const Diagnostics& diag) {
    const auto& sparse = accessor.sparse;
    if (sparse.count < 0 || static_cast<size_t>(sparse.count) > accessor.count) {
        diag.fail(element, "sparse count " + std::to_string(sparse.count) + " is not in [0, " +
                               std::to_string(accessor.count) + "]");
    }
    const int index_type = sparse.indices.componentType;
    if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        diag.fail(element, "sparse indices componentType " + std::to_string(index_type) +
                               " is not an unsigned integer type");
    }
    if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0) {
        diag.fail(element, "negative sparse byteOffset");
    }
    const size_t count = static_cast<size_t>(sparse.count);
    const size_t index_size = component_size(index_type);
    const size_t value_size = component_size(accessor.componentType) * components;
    const ElementRun indices = locate_elements(
        model, sparse.indices.bufferView, static_cast<size_t>(sparse.indices.byteOffset), count,
        index_size, true, element + " sparse indices", diag);
    const ElementRun substitutes = locate_elements(
        model, sparse.values.bufferView, static_cast<size_t>(sparse.values.byteOffset), count,
        value_size, true, element + " sparse values", diag);
    for (size_t i = 0; i < count; ++i) {
        const double target = read_component(indices.data + i * index_size, index_type, false);
        if (target >= static_cast<double>(accessor.count)) {
            diag.fail(element, "sparse index " + std::to_string(static_cast<size_t>(target)) +
                                   " out of range (count " + std::to_string(accessor.count) + ")");
        }
        for (size_t c = 0; c < components; ++c) {
            values[static_cast<size_t>(target) * components + c] = read_component(
                substitutes.data + i * value_size + c * component_size(accessor.componentType),
                accessor.componentType, accessor.normalized);
        }
    }
}

// All components of accessor `index`, element after element, sparse substitution applied.
// Without a bufferView the base values are zeros ("Sparse Accessors").
std::vector<double> read_accessor(const tinygltf::Model& model, int index,
                                  const std::string& referrer, const Diagnostics& diag) {
    const tinygltf::Accessor& accessor =
        checked_at(model.accessors, index, "accessor", referrer, diag);
    const std::string element = element_name("accessor", static_cast<size_t>(index));
    const size_t size = component_size(accessor.componentType);
    const size_t components = components_per_element(accessor.type);
    if (size == 0 || components == 0) {
        diag.fail(element, "unsupported componentType " + std::to_string(accessor.componentType) +
                               " or type " + std::to_string(accessor.type));
    }
    // With a bufferView the data bounds the count; without one only this limit does.
    ElementRun run;
    if (accessor.bufferView != -1) {
        run = locate_elements(model, accessor.bufferView, accessor.byteOffset, accessor.count,
                              size * components, false, element, diag);
    } else if (accessor.count > kMaxZeroBasedCount) {
        diag.fail(element, "count " + std::to_string(accessor.count) +
                               " is too large for an accessor without a bufferView");
    }

    std::vector<double> values(accessor.count * components, 0.0);
    if (run.data != nullptr) {
        for (size_t e = 0; e < accessor.count; ++e) {
            for (size_t c = 0; c < components; ++c) {
                values[e * components + c] =
                    read_component(run.data + e * run.stride + c * size, accessor.componentType,
                                   accessor.normalized);
            }
        }
    }
    if (accessor.sparse.isSparse) apply_sparse(model, accessor, components, values, element, diag);
    return values;
}

const tinygltf::Accessor& accessor_at(const tinygltf::Model& model, int index,
                                      const std::string& referrer, const Diagnostics& diag) {
    return checked_at(model.accessors, index, "accessor", referrer, diag);
}

// POSITION: VEC3 of floats ("Meshes", attribute table), or of (normalized) 8/16-bit integers as
// KHR_mesh_quantization allows. Every component is finite and within kMaxCoordinate.
std::vector<glm::dvec3> read_positions(const tinygltf::Model& model, int index,
                                       const std::string& referrer, const Diagnostics& diag) {
    const tinygltf::Accessor& accessor = accessor_at(model, index, referrer, diag);
    const std::string element = element_name("accessor", static_cast<size_t>(index));
    const int type = accessor.componentType;
    const bool float_or_quantized =
        type == TINYGLTF_COMPONENT_TYPE_FLOAT || type == TINYGLTF_COMPONENT_TYPE_BYTE ||
        type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT ||
        type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    if (accessor.type != TINYGLTF_TYPE_VEC3 || !float_or_quantized) {
        diag.fail(element, "POSITION must be a VEC3 of floats (or of 8/16-bit integers)");
    }
    const std::vector<double> values = read_accessor(model, index, referrer, diag);
    std::vector<glm::dvec3> positions(accessor.count);
    for (size_t v = 0; v < positions.size(); ++v) {
        positions[v] = glm::dvec3(values[3 * v], values[3 * v + 1], values[3 * v + 2]);
        if (!is_finite(positions[v])) {
            diag.fail(element, "POSITION " + std::to_string(v) + " is not finite");
        }
        if (glm::any(glm::greaterThan(glm::abs(positions[v]), glm::dvec3(kMaxCoordinate)))) {
            diag.fail(element, "POSITION " + std::to_string(v) + " exceeds 1e30 in magnitude");
        }
    }
    return positions;
}

// Indices: SCALAR of unsigned bytes, shorts or ints, each < the POSITION count ("Meshes").
std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, size_t vertex_count,
                                   const std::string& referrer, const Diagnostics& diag) {
    const tinygltf::Accessor& accessor = accessor_at(model, index, referrer, diag);
    const std::string element = element_name("accessor", static_cast<size_t>(index));
    const int type = accessor.componentType;
    if (accessor.type != TINYGLTF_TYPE_SCALAR || accessor.normalized ||
        (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
         type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
        diag.fail(element, "indices must be a SCALAR of unsigned bytes, shorts or ints");
    }
    const std::vector<double> values = read_accessor(model, index, referrer, diag);
    std::vector<uint32_t> indices(values.size());
    for (size_t i = 0; i < values.size(); ++i) {
        if (values[i] >= static_cast<double>(vertex_count)) {
            diag.fail(referrer, "index " + std::to_string(static_cast<uint64_t>(values[i])) +
                                    " (at " + std::to_string(i) + " in " + element +
                                    ") out of range of the " + std::to_string(vertex_count) +
                                    " POSITION values");
        }
        indices[i] = static_cast<uint32_t>(values[i]);
    }
    return indices;
}

// ---------------------------------------------------------------------------------------------
// Geometry helpers
// ---------------------------------------------------------------------------------------------

// Vertex ids of the triangles of a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive, three per
// triangle, front face counter-clockwise ("Meshes", topology types table).
std::vector<uint32_t> triangle_list(int mode, const std::vector<uint32_t>& ids) {
    std::vector<uint32_t> corners;
    const size_t n = ids.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        corners.assign(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(n - n % 3));
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // p_i = {v_i, v_{i + (1 + i%2)}, v_{i + (2 − i%2)}}
        for (size_t i = 0; i + 2 < n; ++i) {
            corners.insert(corners.end(), {ids[i], ids[i + 1 + i % 2], ids[i + 2 - i % 2]});
        }
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        // p_i = {v_{i+1}, v_{i+2}, v_0}
        for (size_t i = 0; i + 2 < n; ++i) {
            corners.insert(corners.end(), {ids[i + 1], ids[i + 2], ids[0]});
        }
    }
    return corners;
}

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

// ---------------------------------------------------------------------------------------------
// The importer: walks the default scene and fills a Scene.
// ---------------------------------------------------------------------------------------------

class Importer {
  public:
    Importer(const tinygltf::Model& model, Diagnostics& diag) : model_(model), diag_(diag) {}

    Scene import_default_scene(const std::string& path);

  private:
    struct Roots {
        std::vector<int> nodes;
        std::string element;  // who lists them, for errors
    };
    Roots root_nodes();
    void check_asset();
    void check_expansion(const Roots& roots);
    void traverse(const Roots& roots);
    void merge_duplicate_emitters();
    glm::dmat4 local_transform(int node_index);
    void visit_node(int node_index, const glm::dmat4& world);
    void import_primitive(const tinygltf::Primitive& primitive, const std::string& element,
                          const glm::dmat4& world, const std::string& node_element);
    void import_camera(int camera_index, const glm::dmat4& world, int node_index);
    uint32_t material_slot(int material_index, const std::string& referrer);
    Material convert_material(int material_index, const std::string& referrer);
    double emissive_strength(const tinygltf::Material& material, const std::string& element);
    void read_microfacet_factors(const tinygltf::Material& source, const std::string& element,
                                 Material& material);
    float unit_factor(double value, const char* what, const std::string& element);
    void warn_unsupported_material_parts(const tinygltf::Material& material);
    void warn_unsupported_model_parts();

    const tinygltf::Model& model_;
    Diagnostics& diag_;
    Scene scene_;
    std::map<int, uint32_t> material_slots_;  // glTF material index (−1: default) → Scene slot
    double total_power_ = 0.0;                // of every emissive triangle instance, in double
    double max_coordinate_ = 0.0;             // largest |component| of a world position
};

Scene Importer::import_default_scene(const std::string& path) {
    scene_.path = path;
    check_asset();
    warn_unsupported_model_parts();
    const Roots roots = root_nodes();
    check_expansion(roots);
    traverse(roots);
    // Light selection divides by shares of the total: it must be a float too.
    if (!(total_power_ <= 0.5 * std::numeric_limits<float>::max())) {
        diag_.fail("the emitters' summed power " + format_number(total_power_) +
                   " overflows single precision (too many or too bright emitters)");
    }
    merge_duplicate_emitters();
    if (max_coordinate_ > kWarnCoordinate) {
        diag_.warn_once("coordinates", "coordinates up to " + format_number(max_coordinate_) +
                                           " exceed " + format_number(kWarnCoordinate) +
                                           ": float traversal may lose triangles");
    }
    return std::move(scene_);
}

// "Asset": version 2.x, minVersion at most 2.0; "Specifying Extensions": every extension in
// extensionsRequired must be supported.
void Importer::check_asset() {
    const std::string& version = model_.asset.version;
    if (version.size() < 3 || version.compare(0, 2, "2.") != 0 ||
        version.find_first_not_of("0123456789", 2) != std::string::npos) {
        diag_.fail("asset.version \"" + version + "\" is not 2.x (glTF 2.0 is read)");
    }
    const std::string& min_version = model_.asset.minVersion;
    if (!min_version.empty() && min_version != "2.0") {
        diag_.fail("asset.minVersion \"" + min_version + "\" is newer than the 2.0 mcrt reads");
    }
    for (const std::string& extension : model_.extensionsRequired) {
        if (!kSupportedRequiredExtensions.count(extension)) {
            diag_.fail("extensionsRequired names " + extension + ", which mcrt does not implement");
        }
    }
}

// Node instances and triangles each root expands to, counted bottom-up per node (a shared
// subtree once) before anything is expanded, so an exponential hierarchy is refused at once.
// Triangle counts are upper bounds from the accessor counts; cycles are left to traverse().
void Importer::check_expansion(const Roots& roots) {
    const size_t n = model_.nodes.size();
    constexpr double kUnknown = -1.0;
    std::vector<double> instances(n, kUnknown), triangles(n, kUnknown);
    std::vector<char> on_stack(n, 0);
    auto mesh_triangles = [&](int mesh_index) {
        double count = 0.0;
        if (mesh_index < 0 || static_cast<size_t>(mesh_index) >= model_.meshes.size()) return count;
        for (const tinygltf::Primitive& p : model_.meshes[static_cast<size_t>(mesh_index)].primitives) {
            int accessor = p.indices;
            if (accessor == -1) {
                const auto position = p.attributes.find("POSITION");
                accessor = position == p.attributes.end() ? -1 : position->second;
            }
            if (accessor >= 0 && static_cast<size_t>(accessor) < model_.accessors.size())
                count += static_cast<double>(model_.accessors[static_cast<size_t>(accessor)].count);
        }
        return count;  // ≥ the triangles of any mode
    };
    struct Frame {
        int node;
        size_t next_child;
    };
    std::vector<Frame> stack;
    auto valid = [&](int node) { return node >= 0 && static_cast<size_t>(node) < n; };
    double total_instances = 0.0, total_triangles = 0.0;
    for (int root : roots.nodes) {
        if (!valid(root)) continue;  // traverse() names it
        if (instances[static_cast<size_t>(root)] == kUnknown) {
            stack.push_back(Frame{root, 0});
            on_stack[static_cast<size_t>(root)] = 1;
            while (!stack.empty()) {
                Frame& top = stack.back();
                const auto& children = model_.nodes[static_cast<size_t>(top.node)].children;
                if (top.next_child < children.size()) {
                    const int child = children[top.next_child++];
                    if (!valid(child) || on_stack[static_cast<size_t>(child)] ||
                        instances[static_cast<size_t>(child)] != kUnknown)
                        continue;  // invalid or cyclic: traverse() names it
                    on_stack[static_cast<size_t>(child)] = 1;
                    stack.push_back(Frame{child, 0});
                    continue;
                }
                const size_t node = static_cast<size_t>(top.node);
                double i = 1.0, t = mesh_triangles(model_.nodes[node].mesh);
                for (int child : children) {
                    if (!valid(child) || instances[static_cast<size_t>(child)] == kUnknown) continue;
                    i += instances[static_cast<size_t>(child)];
                    t += triangles[static_cast<size_t>(child)];
                }
                instances[node] = i;
                triangles[node] = t;
                on_stack[node] = 0;
                stack.pop_back();
            }
        }
        total_instances += instances[static_cast<size_t>(root)];
        total_triangles += triangles[static_cast<size_t>(root)];
    }
    if (total_instances > static_cast<double>(kMaxNodeInstances)) {
        diag_.fail("the node hierarchy expands to " + format_number(total_instances) +
                   " node instances, more than " + std::to_string(kMaxNodeInstances));
    }
    if (total_triangles > 3.0 * static_cast<double>(kMaxTriangles)) {
        diag_.fail("the node hierarchy expands to up to " + format_number(total_triangles / 3.0) +
                   " triangles, more than " + std::to_string(kMaxTriangles));
    }
}

// The same emissive triangle twice (same material, same corners in the same winding; either
// winding when double-sided) is one surface a ray hits once, but light sampling would count it
// twice: keep the first, drop the copies, warn once.
void Importer::merge_duplicate_emitters() {
    struct Key {
        std::array<float, 9> corners;
        uint32_t material;
        bool operator==(const Key& o) const { return corners == o.corners && material == o.material; }
    };
    struct KeyHash {
        size_t operator()(const Key& k) const {
            size_t h = std::hash<uint32_t>()(k.material);
            for (float f : k.corners) h = h * 1000003u ^ std::hash<float>()(f);
            return h;
        }
    };
    auto key_of = [&](size_t t) {
        std::array<glm::vec3, 3> v = {scene_.positions[3 * t], scene_.positions[3 * t + 1],
                                      scene_.positions[3 * t + 2]};
        auto less = [](const glm::vec3& a, const glm::vec3& b) {
            return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
        };
        const uint32_t material = scene_.triangle_material[t];
        if (scene_.materials[material].double_sided) {
            std::sort(v.begin(), v.end(), less);
        } else {  // rotate the smallest corner first: the winding is kept
            const size_t first = static_cast<size_t>(std::min_element(v.begin(), v.end(), less) - v.begin());
            std::rotate(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(first), v.end());
        }
        Key key{{v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z}, material};
        return key;
    };
    std::unordered_map<Key, size_t, KeyHash> seen;
    std::vector<char> drop(scene_.triangle_count(), 0);
    size_t dropped = 0;
    for (size_t t = 0; t < scene_.triangle_count(); ++t) {
        if (!(luminance(scene_.materials[scene_.triangle_material[t]].emission) > 0.0f)) continue;
        if (!seen.emplace(key_of(t), t).second) drop[t] = 1, ++dropped;
    }
    if (dropped == 0) return;
    size_t kept = 0;
    for (size_t t = 0; t < scene_.triangle_count(); ++t) {
        if (drop[t]) continue;
        for (int c = 0; c < 3; ++c) scene_.positions[3 * kept + c] = scene_.positions[3 * t + c];
        scene_.triangle_material[kept++] = scene_.triangle_material[t];
    }
    scene_.positions.resize(3 * kept);
    scene_.triangle_material.resize(kept);
    diag_.warn_once("duplicate-emitters",
                    std::to_string(dropped) +
                        " emissive triangle(s) repeat another exactly (same corners and material); "
                        "the copies are dropped so that each surface emits once");
}

// The `scene` property's scene, else scene 0 ("Scenes"); a file without scenes renders its
// root nodes (those no node lists as a child).
Importer::Roots Importer::root_nodes() {
    if (model_.defaultScene != -1 || !model_.scenes.empty()) {
        const int index = model_.defaultScene == -1 ? 0 : model_.defaultScene;
        const tinygltf::Scene& scene =
            checked_at(model_.scenes, index, "scene", "scene property", diag_);
        return Roots{scene.nodes, element_name("scene", static_cast<size_t>(index))};
    }
    if (model_.nodes.empty()) diag_.fail("no scenes and no nodes: nothing to render");
    std::vector<char> is_child(model_.nodes.size(), 0);
    for (size_t n = 0; n < model_.nodes.size(); ++n) {
        for (int child : model_.nodes[n].children) {
            checked_at(model_.nodes, child, "child", element_name("node", n), diag_);
            is_child[static_cast<size_t>(child)] = 1;
        }
    }
    std::vector<int> roots;
    for (size_t n = 0; n < model_.nodes.size(); ++n) {
        if (!is_child[n]) roots.push_back(static_cast<int>(n));
    }
    // Following parents from any node then never ends: the hierarchy holds a cycle.
    if (roots.empty()) diag_.fail("node cycle: every node is the child of another");
    return Roots{roots, "root nodes"};
}

// Depth-first, pre-order, children in order ("Nodes and Hierarchy"). An explicit stack, so deep
// hierarchies cannot overflow the call stack; a node already on the path is a cycle, a node met
// again elsewhere is a shared subtree and is instanced.
void Importer::traverse(const Roots& roots) {
    struct Frame {
        int node;
        glm::dmat4 world;
        size_t next_child;
    };
    std::vector<char> on_path(model_.nodes.size(), 0);
    std::vector<Frame> stack;
    size_t instances = 0;

    auto enter = [&](int node, const glm::dmat4& parent_world) {
        if (on_path[static_cast<size_t>(node)]) {
            diag_.fail("node cycle through node " + std::to_string(node));
        }
        if (++instances > kMaxNodeInstances) {
            diag_.fail("the node hierarchy expands to more than " +
                       std::to_string(kMaxNodeInstances) + " node instances");
        }
        const glm::dmat4 world = parent_world * local_transform(node);
        on_path[static_cast<size_t>(node)] = 1;
        visit_node(node, world);
        stack.push_back(Frame{node, world, 0});
    };

    for (int root : roots.nodes) {
        checked_at(model_.nodes, root, "node", roots.element, diag_);
        enter(root, glm::dmat4(1.0));
        while (!stack.empty()) {
            Frame& top = stack.back();
            const tinygltf::Node& node = model_.nodes[static_cast<size_t>(top.node)];
            if (top.next_child == node.children.size()) {
                on_path[static_cast<size_t>(top.node)] = 0;
                stack.pop_back();
                continue;
            }
            const int child = node.children[top.next_child++];
            checked_at(model_.nodes, child, "child",
                       element_name("node", static_cast<size_t>(top.node)), diag_);
            const glm::dmat4 parent_world = top.world;  // `top` dies when `enter` grows the stack
            enter(child, parent_world);
        }
    }
}

// "Transformations": a column-major `matrix`, or T·R·S with the rotation a unit quaternion
// [x, y, z, w].
glm::dmat4 Importer::local_transform(int node_index) {
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
    const std::string element = element_name("node", static_cast<size_t>(node_index));
    auto check = [&](const std::vector<double>& values, size_t size, const char* name) {
        if (!values.empty() && values.size() != size) {
            diag_.fail(element,
                       std::string(name) + " must have " + std::to_string(size) + " numbers");
        }
        if (!all_finite(values)) diag_.fail(element, std::string(name) + " is not finite");
    };
    check(node.matrix, 16, "matrix");
    check(node.translation, 3, "translation");
    check(node.rotation, 4, "rotation");
    check(node.scale, 3, "scale");

    if (!node.matrix.empty()) {
        const glm::dmat4 m = glm::make_mat4(node.matrix.data());
        // "Transformations": a matrix must decompose into T·R·S, so its last row is 0 0 0 1.
        if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) {
            diag_.fail(element, "matrix is projective (its last row is not 0 0 0 1)");
        }
        if (glm::determinant(glm::dmat3(m)) == 0.0) {
            diag_.warn_once("singular", element + ": transform is singular (zero scale): its "
                                                  "geometry collapses and is degenerate");
        }
        return m;
    }

    glm::dmat4 transform(1.0);
    if (!node.translation.empty())
        transform = glm::translate(transform, glm::make_vec3(node.translation.data()));
    if (!node.rotation.empty()) {
        const auto& r = node.rotation;
        const glm::dquat q(r[3], r[0], r[1], r[2]);  // glm takes w first
        const double length = glm::length(q);
        if (!(length > 0.0)) diag_.fail(element, "rotation is a zero quaternion");
        transform *= glm::mat4_cast(q / length);
    }
    if (!node.scale.empty()) transform = glm::scale(transform, glm::make_vec3(node.scale.data()));
    if (glm::determinant(glm::dmat3(transform)) == 0.0) {
        diag_.warn_once("singular", element + ": transform is singular (zero scale): its "
                                              "geometry collapses and is degenerate");
    }
    return transform;
}

void Importer::visit_node(int node_index, const glm::dmat4& world) {
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
    const std::string element = element_name("node", static_cast<size_t>(node_index));
    if (node.skin != -1)
        diag_.warn_once("skins", "skins are not supported; meshes keep their bind pose");
    if (!node.weights.empty()) {
        diag_.warn_once("morph", "morph targets are not supported; base geometry used");
    }
    if (node.extensions.count("KHR_lights_punctual")) {
        diag_.warn_once("lights", "KHR_lights_punctual lights are not supported; ignored");
    }
    if (node.mesh != -1) {
        const tinygltf::Mesh& mesh = checked_at(model_.meshes, node.mesh, "mesh", element, diag_);
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const std::string primitive_element =
                element_name("mesh", static_cast<size_t>(node.mesh)) + " primitive " +
                std::to_string(p);
            import_primitive(mesh.primitives[p], primitive_element, world, element);
        }
    }
    if (node.camera != -1) import_camera(node.camera, world, node_index);
}

void Importer::import_primitive(const tinygltf::Primitive& primitive, const std::string& element,
                                const glm::dmat4& world, const std::string& node_element) {
    if (!primitive.targets.empty()) {
        diag_.warn_once("morph", "morph targets are not supported; base geometry used");
    }
    const int mode = primitive.mode == -1 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
        diag_.warn_once("points-lines", "points and lines are not supported; skipped");
        return;
    }
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        diag_.fail(element, "invalid mode " + std::to_string(mode));
    }
    const auto position = primitive.attributes.find("POSITION");
    if (position == primitive.attributes.end()) {
        diag_.warn_once("no-position", "primitives without POSITION are skipped");
        return;
    }

    // Geometry in the node's frame, checked again after the transform.
    std::vector<glm::dvec3> positions = read_positions(model_, position->second, element, diag_);
    for (glm::dvec3& p : positions) {
        p = glm::dvec3(world * glm::dvec4(p, 1.0));
        if (!is_finite(p) || glm::any(glm::greaterThan(glm::abs(p), glm::dvec3(kMaxCoordinate)))) {
            diag_.fail(node_element, "transformed position of " + element +
                                         " is not finite or exceeds 1e30 in magnitude");
        }
        max_coordinate_ = std::max(max_coordinate_, max_component(glm::abs(p)));
    }
    std::vector<uint32_t> ids(positions.size());
    if (primitive.indices != -1) {
        ids = read_indices(model_, primitive.indices, positions.size(), element, diag_);
    } else {
        for (size_t v = 0; v < ids.size(); ++v) ids[v] = static_cast<uint32_t>(v);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && ids.size() % 3 != 0) {
        diag_.fail(element, std::to_string(ids.size()) + (primitive.indices != -1 ? " indices" : " vertices") +
                                " are not a multiple of 3 (mode TRIANGLES)");
    }
    const std::vector<uint32_t> corners = triangle_list(mode, ids);
    const size_t triangles = corners.size() / 3;
    if (scene_.triangle_count() + triangles > kMaxTriangles) {
        diag_.fail("more than " + std::to_string(kMaxTriangles) + " triangles");
    }

    // A mirroring transform turns counter-clockwise into clockwise: swap two corners so the
    // front face stays the one the file means.
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
    const uint32_t material = material_slot(primitive.material, element);
    const Material& surface = scene_.materials[material];
    const double Le_luminance = luminance(surface.emission);
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t a = corners[3 * t], b = corners[3 * t + 1], c = corners[3 * t + 2];
        // An emitter's power, luminance(Le) × area × π (×2 double-sided), is a float in light
        // selection (scene.h EmissiveTriangle): it must not overflow (found by fuzzing).
        if (Le_luminance > 0.0) {
            const double area = 0.5 * glm::length(glm::cross(positions[b] - positions[a],
                                                             positions[c] - positions[a]));
            const double power =
                Le_luminance * area * glm::pi<double>() * (surface.double_sided ? 2.0 : 1.0);
            if (!(power <= 0.5 * std::numeric_limits<float>::max())) {
                diag_.fail(element, "triangle " + std::to_string(t) + ": emitted power " +
                                        format_number(power) +
                                        " overflows single precision (emission × area too large)");
            }
            total_power_ += power;
        }
        scene_.positions.push_back(glm::vec3(positions[a]));
        scene_.positions.push_back(glm::vec3(positions[mirrored ? c : b]));
        scene_.positions.push_back(glm::vec3(positions[mirrored ? b : c]));
        scene_.triangle_material.push_back(material);
    }
}

// "Cameras": perspective cameras only; the node's transform without its scale.
void Importer::import_camera(int camera_index, const glm::dmat4& world, int node_index) {
    const std::string node_element = element_name("node", static_cast<size_t>(node_index));
    const tinygltf::Camera& camera =
        checked_at(model_.cameras, camera_index, "camera", node_element, diag_);
    const std::string element = element_name("camera", static_cast<size_t>(camera_index));
    if (camera.type == "orthographic") {
        diag_.warn_once("orthographic", "orthographic cameras are not supported; ignored");
        return;
    }
    if (camera.type != "perspective") diag_.fail(element, "unknown type \"" + camera.type + "\"");
    const double yfov = camera.perspective.yfov;
    if (!(yfov > 0.0 && yfov < glm::pi<double>())) {
        diag_.fail(element, "yfov " + format_number(yfov) + " is not in (0, pi)");
    }
    glm::dmat4 frame;
    if (!rigid_frame(world, frame)) diag_.fail(node_element, "camera transform is degenerate");

    Camera result;
    result.name = !camera.name.empty() ? camera.name
                  : !model_.nodes[static_cast<size_t>(node_index)].name.empty()
                      ? model_.nodes[static_cast<size_t>(node_index)].name
                      : element;
    result.camera_to_world = glm::mat4(frame);
    result.yfov = static_cast<float>(yfov);
    scene_.cameras.push_back(result);
}

// The Scene slot of glTF material `material_index` (−1: the default material), converted once.
uint32_t Importer::material_slot(int material_index, const std::string& referrer) {
    const auto found = material_slots_.find(material_index);
    if (found != material_slots_.end()) return found->second;

    Material material;
    if (material_index == -1) {
        // "Materials": the default material is white, not emissive, single-sided, with the
        // metallic-roughness defaults (metallic 1, roughness 1) and the specular layer of
        // KHR_materials_specular's defaults.
        material.name = "default";
        material.metallic = 1.0f;
        material.roughness = 1.0f;
        material.specular = 1.0f;
    } else {
        material = convert_material(material_index, referrer);
    }
    const uint32_t slot = static_cast<uint32_t>(scene_.materials.size());
    scene_.materials.push_back(material);
    material_slots_.emplace(material_index, slot);
    return slot;
}

// DESIGN.md "Radiometric contract": albedo = baseColorFactor.rgb,
// Le = emissiveFactor × KHR_materials_emissive_strength.emissiveStrength.
Material Importer::convert_material(int material_index, const std::string& referrer) {
    const tinygltf::Material& source =
        checked_at(model_.materials, material_index, "material", referrer, diag_);
    const std::string element = element_name("material", static_cast<size_t>(material_index));
    warn_unsupported_material_parts(source);

    const std::vector<double>& base = source.pbrMetallicRoughness.baseColorFactor;
    if (base.size() != 4 || !all_finite(base) ||
        *std::min_element(base.begin(), base.end()) < 0.0) {
        diag_.fail(element, "baseColorFactor must be 4 finite non-negative numbers");
    }
    const std::vector<double>& emissive = source.emissiveFactor;
    if (!emissive.empty() && (emissive.size() != 3 || !all_finite(emissive) ||
                              *std::min_element(emissive.begin(), emissive.end()) < 0.0)) {
        diag_.fail(element, "emissiveFactor must be 3 finite non-negative numbers");
    }

    Material material;
    material.name = source.name.empty() ? element : source.name;
    glm::dvec3 albedo(base[0], base[1], base[2]);
    if (max_component(albedo) > 1.0) {
        // An albedo above 1 reflects more than arrives: energy from nothing.
        diag_.warn_once("albedo", element + ": baseColorFactor " + format_number(max_component(albedo)) +
                                      " is above 1; factors are clamped to [0, 1]");
        albedo = glm::min(albedo, glm::dvec3(1.0));
    }
    material.albedo = glm::vec3(albedo);
    if (!emissive.empty()) {
        const glm::dvec3 Le =
            glm::dvec3(emissive[0], emissive[1], emissive[2]) * emissive_strength(source, element);
        material.emission = glm::vec3(Le);
        if (!is_finite(glm::dvec3(material.emission))) {
            diag_.fail(element, "emission overflows single precision");
        }
        if (max_component(Le) > kMaxRadiance) {
            diag_.fail(element, "emission " + format_number(max_component(Le)) + " exceeds " +
                                    format_number(kMaxRadiance) +
                                    ", beyond which an estimate may overflow single precision");
        }
    }
    material.double_sided = source.doubleSided;
    read_microfacet_factors(source, element, material);
    return material;
}

// A factor the specification bounds to [0, 1]: NaN and infinities fail, others are clamped
// with one warning.
float Importer::unit_factor(double value, const char* what, const std::string& element) {
    if (!std::isfinite(value)) diag_.fail(element, std::string(what) + " must be a finite number");
    if (value < 0.0 || value > 1.0) {
        diag_.warn_once(std::string("factor-") + what,
                        element + ": " + what + " " + format_number(value) +
                            " is outside [0, 1]; clamped");
        value = std::clamp(value, 0.0, 1.0);
    }
    return float(value);
}

// glTF 2.0 Appendix B's parameters: metallicFactor, roughnessFactor (default 1 each), and
// KHR_materials_specular's specularFactor (default 1) and specularColorFactor (default 1, 1, 1;
// F0 = min(0.04 × it, 1) is clamped where the BRDF is built, host/render/gpu_scene.cpp).
void Importer::read_microfacet_factors(const tinygltf::Material& source,
                                       const std::string& element, Material& material) {
    const auto& pbr = source.pbrMetallicRoughness;
    material.metallic = unit_factor(pbr.metallicFactor, "metallicFactor", element);
    material.roughness = unit_factor(pbr.roughnessFactor, "roughnessFactor", element);
    material.specular = 1.0f;
    material.specular_color = glm::vec3(1.0f);
    const auto extension = source.extensions.find("KHR_materials_specular");
    if (extension == source.extensions.end() || !extension->second.IsObject()) return;
    const tinygltf::Value& ext = extension->second;
    if (ext.Has("specularFactor")) {
        const tinygltf::Value& v = ext.Get("specularFactor");
        material.specular =
            unit_factor(v.IsNumber() ? v.GetNumberAsDouble()
                                     : std::numeric_limits<double>::quiet_NaN(),
                        "KHR_materials_specular.specularFactor", element);
    }
    if (ext.Has("specularColorFactor")) {
        const tinygltf::Value& v = ext.Get("specularColorFactor");
        bool ok = v.IsArray() && v.ArrayLen() == 3;
        glm::dvec3 c(0.0);
        for (int k = 0; ok && k < 3; ++k) {
            ok = v.Get(k).IsNumber();
            if (ok) c[k] = v.Get(k).GetNumberAsDouble();
            ok = ok && std::isfinite(c[k]) && c[k] >= 0.0 && c[k] <= 1e30;
        }
        if (!ok) {
            diag_.fail(element,
                       "KHR_materials_specular.specularColorFactor must be 3 finite "
                       "non-negative numbers");
        }
        material.specular_color = glm::vec3(c);
    }
}

// KHR_materials_emissive_strength: a non-negative multiplier of emissiveFactor, 1 when absent.
double Importer::emissive_strength(const tinygltf::Material& material, const std::string& element) {
    const auto extension = material.extensions.find("KHR_materials_emissive_strength");
    if (extension == material.extensions.end()) return 1.0;
    if (!extension->second.IsObject() || !extension->second.Has("emissiveStrength")) return 1.0;
    const tinygltf::Value& value = extension->second.Get("emissiveStrength");
    const double strength =
        value.IsNumber() ? value.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
    if (!(strength >= 0.0) || !std::isfinite(strength)) {
        diag_.fail(element,
                   "KHR_materials_emissive_strength.emissiveStrength must be a finite "
                   "non-negative number");
    }
    return strength;
}

void Importer::warn_unsupported_material_parts(const tinygltf::Material& material) {
    const auto& pbr = material.pbrMetallicRoughness;
    if (pbr.baseColorTexture.index != -1 || pbr.metallicRoughnessTexture.index != -1 ||
        material.normalTexture.index != -1 || material.occlusionTexture.index != -1 ||
        material.emissiveTexture.index != -1) {
        diag_.warn_once("textures", "textures are not supported; material factors used alone");
    }
    if (material.alphaMode != "OPAQUE") {
        diag_.warn_once(
            "alpha", "alphaMode " + material.alphaMode + " is not supported; surfaces are opaque");
    }
    if (material.extensions.count("KHR_materials_transmission")) {
        diag_.warn_once("transmission",
                        "KHR_materials_transmission is not supported; surfaces are opaque "
                        "(reflection only)");
    }
}

void Importer::warn_unsupported_model_parts() {
    if (!model_.lights.empty()) {
        diag_.warn_once("lights", "KHR_lights_punctual lights are not supported; ignored");
    }
    if (!model_.animations.empty()) {
        diag_.warn_once("animations", "animations are not supported; the rest pose is used");
    }
    if (!model_.skins.empty()) {
        diag_.warn_once("skins", "skins are not supported; meshes keep their bind pose");
    }
}

}  // namespace

Scene load_gltf(const std::string& path, const WarningSink& warn,
                std::vector<std::string>* files_read, FileBundle* record) {
    DiskAccess access;
    access.record = record;
    const tinygltf::Model model = read_model(path, files_read, std::move(access));
    Diagnostics diag(path, warn);
    return Importer(model, diag).import_default_scene(path);
}

Scene load_gltf_from_bundle(const std::string& path, const FileBundle& files,
                            const WarningSink& warn) {
    DiskAccess access;
    access.source = &files;
    const tinygltf::Model model = read_model(path, nullptr, std::move(access));
    Diagnostics diag(path, warn);
    return Importer(model, diag).import_default_scene(path);
}

Scene load_gltf_from_memory(const std::string& name, const std::vector<unsigned char>& bytes,
                            const WarningSink& warn) {
    const tinygltf::Model model = read_model_from_memory(name, bytes);
    Diagnostics diag(name, warn);
    return Importer(model, diag).import_default_scene(name);
}

}  // namespace mcrt
