// Accessors ("Accessors", "Accessor Data Types", "Sparse Accessors", "Data Alignment"): the
// typed values of a buffer view read as doubles, every byte range checked first.
#include "scene/gltf_accessors.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "scene/gltf_limits.h"

namespace mcrt::gltf {

namespace {

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

// A componentType with its normalized flag, as an attribute's accessor may have it.
struct ComponentFormat {
    int component_type;
    bool normalized;
};

constexpr ComponentFormat kFloat{TINYGLTF_COMPONENT_TYPE_FLOAT, false};
constexpr ComponentFormat kNormalizedByte{TINYGLTF_COMPONENT_TYPE_BYTE, true};
constexpr ComponentFormat kNormalizedUnsignedByte{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true};
constexpr ComponentFormat kNormalizedShort{TINYGLTF_COMPONENT_TYPE_SHORT, true};
constexpr ComponentFormat kNormalizedUnsignedShort{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true};

// What a vertex attribute other than POSITION must be: its type (VEC2, ...), the component
// formats it may use, and how a message says so.
struct AttributeFormat {
    int type;
    std::vector<ComponentFormat> formats;
    const char* description;  // "a VEC3 of floats ..."
};

// The components of attribute accessor `index`: of `format`, `vertex_count` elements, finite.
std::vector<double> read_vertex_attribute(const tinygltf::Model& model, int index,
                                          size_t vertex_count, const std::string& attribute,
                                          const AttributeFormat& format,
                                          const std::string& referrer, const Diagnostics& diag) {
    const tinygltf::Accessor& accessor =
        checked_at(model.accessors, index, "accessor", referrer, diag);
    const std::string element = element_name("accessor", static_cast<size_t>(index));
    const bool allowed =
        std::any_of(format.formats.begin(), format.formats.end(), [&](const ComponentFormat& f) {
            return f.component_type == accessor.componentType &&
                   f.normalized == accessor.normalized;
        });
    if (accessor.type != format.type || !allowed) {
        diag.fail(element, attribute + " must be " + format.description);
    }
    if (accessor.count != vertex_count) {
        diag.fail(referrer, attribute + " (" + element + ") has " + std::to_string(accessor.count) +
                                " values, POSITION has " + std::to_string(vertex_count));
    }
    const std::vector<double> values = read_accessor(model, index, referrer, diag);
    const size_t components = components_per_element(accessor.type);
    for (size_t i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i])) {
            diag.fail(element, attribute + " " + std::to_string(i / components) + " is not finite");
        }
    }
    return values;
}

}  // namespace

std::vector<glm::dvec3> read_positions(const tinygltf::Model& model, int index,
                                       const std::string& referrer, const Diagnostics& diag) {
    const tinygltf::Accessor& accessor =
        checked_at(model.accessors, index, "accessor", referrer, diag);
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

std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, size_t vertex_count,
                                   const std::string& referrer, const Diagnostics& diag) {
    const tinygltf::Accessor& accessor =
        checked_at(model.accessors, index, "accessor", referrer, diag);
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

std::vector<glm::dvec2> read_texcoords(const tinygltf::Model& model, int index, size_t vertex_count,
                                       const std::string& attribute, const std::string& referrer,
                                       const Diagnostics& diag) {
    const AttributeFormat format{
        TINYGLTF_TYPE_VEC2,
        {kFloat, kNormalizedUnsignedByte, kNormalizedUnsignedShort, kNormalizedByte,
         kNormalizedShort, ComponentFormat{TINYGLTF_COMPONENT_TYPE_BYTE, false},
         ComponentFormat{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false},
         ComponentFormat{TINYGLTF_COMPONENT_TYPE_SHORT, false},
         ComponentFormat{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false}},
        "a VEC2 of floats or of normalized unsigned bytes or shorts (or, with "
        "KHR_mesh_quantization, of 8/16-bit integers)"};
    const std::vector<double> values =
        read_vertex_attribute(model, index, vertex_count, attribute, format, referrer, diag);
    std::vector<glm::dvec2> texcoords(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) {
        texcoords[v] = glm::dvec2(values[2 * v], values[2 * v + 1]);
    }
    return texcoords;
}

std::vector<glm::dvec3> read_normals(const tinygltf::Model& model, int index, size_t vertex_count,
                                     const std::string& referrer, const Diagnostics& diag) {
    const AttributeFormat format{TINYGLTF_TYPE_VEC3,
                                 {kFloat, kNormalizedByte, kNormalizedShort},
                                 "a VEC3 of floats (or, with KHR_mesh_quantization, of normalized "
                                 "bytes or shorts)"};
    const std::vector<double> values =
        read_vertex_attribute(model, index, vertex_count, "NORMAL", format, referrer, diag);
    std::vector<glm::dvec3> normals(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) {
        normals[v] = glm::dvec3(values[3 * v], values[3 * v + 1], values[3 * v + 2]);
    }
    return normals;
}

std::vector<glm::dvec4> read_tangents(const tinygltf::Model& model, int index, size_t vertex_count,
                                      const std::string& referrer, const Diagnostics& diag) {
    const AttributeFormat format{TINYGLTF_TYPE_VEC4,
                                 {kFloat, kNormalizedByte, kNormalizedShort},
                                 "a VEC4 of floats (or, with KHR_mesh_quantization, of normalized "
                                 "bytes or shorts)"};
    const std::vector<double> values =
        read_vertex_attribute(model, index, vertex_count, "TANGENT", format, referrer, diag);
    std::vector<glm::dvec4> tangents(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) {
        tangents[v] =
            glm::dvec4(values[4 * v], values[4 * v + 1], values[4 * v + 2], values[4 * v + 3]);
    }
    return tangents;
}

}  // namespace mcrt::gltf
