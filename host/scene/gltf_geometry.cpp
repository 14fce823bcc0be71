// Mesh primitives ("Meshes") as world-space triangles of mcrt's Scene: topology, mirroring
// transforms, the corners' texture attributes, the emitted power of each emitter, and duplicate
// emitters merged.
#include "scene/gltf_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <limits>
#include <tuple>
#include <unordered_map>

#include "scene/gltf_accessors.h"
#include "scene/gltf_attributes.h"
#include "scene/gltf_limits.h"

namespace mcrt::gltf {

namespace {

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

// The first textured primitive gives the scene its corner attributes: the corners before it are
// of untextured materials and read none (zero).
void start_corner_attributes(Scene& scene) {
    scene.texcoords.assign(scene.positions.size(), glm::vec4(0.0f));
    scene.normals.assign(scene.positions.size(), glm::vec3(0.0f));
    scene.tangents.assign(scene.positions.size(), glm::vec4(0.0f));
}

// Corner `corner` of `attributes` appended to the scene's; zero for what the primitive's
// material does not read.
void append_corner_attributes(Scene& scene, const CornerAttributes& attributes, size_t corner) {
    auto at = [corner](const auto& values, auto zero) {
        return values.empty() ? zero : values[corner];
    };
    scene.texcoords.push_back(at(attributes.texcoords, glm::vec4(0.0f)));
    scene.normals.push_back(at(attributes.normals, glm::vec3(0.0f)));
    scene.tangents.push_back(at(attributes.tangents, glm::vec4(0.0f)));
}

// The same emissive triangle twice (same material, same corners in the same winding; either
// winding when double-sided) is one surface a ray hits once, but light sampling would count it
// twice: keep the first, drop the copies, warn once.
void merge_duplicate_emitters(Scene& scene, Diagnostics& diag) {
    struct Key {
        std::array<float, 9> corners;
        uint32_t material;
        bool operator==(const Key& o) const {
            return corners == o.corners && material == o.material;
        }
    };
    struct KeyHash {
        size_t operator()(const Key& k) const {
            size_t h = std::hash<uint32_t>()(k.material);
            for (float f : k.corners) h = h * 1000003u ^ std::hash<float>()(f);
            return h;
        }
    };
    auto key_of = [&](size_t t) {
        std::array<glm::vec3, 3> v = {scene.positions[3 * t], scene.positions[3 * t + 1],
                                      scene.positions[3 * t + 2]};
        auto less = [](const glm::vec3& a, const glm::vec3& b) {
            return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
        };
        const uint32_t material = scene.triangle_material[t];
        if (scene.materials[material].double_sided) {
            std::sort(v.begin(), v.end(), less);
        } else {  // rotate the smallest corner first: the winding is kept
            const size_t first =
                static_cast<size_t>(std::min_element(v.begin(), v.end(), less) - v.begin());
            std::rotate(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(first), v.end());
        }
        Key key{{v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z}, material};
        return key;
    };
    std::unordered_map<Key, size_t, KeyHash> seen;
    std::vector<char> drop(scene.triangle_count(), 0);
    size_t dropped = 0;
    for (size_t t = 0; t < scene.triangle_count(); ++t) {
        if (!(luminance(scene.materials[scene.triangle_material[t]].emission) > 0.0f)) continue;
        if (!seen.emplace(key_of(t), t).second) drop[t] = 1, ++dropped;
    }
    if (dropped == 0) return;
    // The corner attributes move with their positions.
    const bool textured = scene.textured();
    size_t kept = 0;
    for (size_t t = 0; t < scene.triangle_count(); ++t) {
        if (drop[t]) continue;
        for (size_t c = 0; c < 3; ++c) {
            scene.positions[3 * kept + c] = scene.positions[3 * t + c];
            if (textured) {
                scene.texcoords[3 * kept + c] = scene.texcoords[3 * t + c];
                scene.normals[3 * kept + c] = scene.normals[3 * t + c];
                scene.tangents[3 * kept + c] = scene.tangents[3 * t + c];
            }
        }
        scene.triangle_material[kept++] = scene.triangle_material[t];
    }
    scene.positions.resize(3 * kept);
    scene.triangle_material.resize(kept);
    if (textured) {
        scene.texcoords.resize(3 * kept);
        scene.normals.resize(3 * kept);
        scene.tangents.resize(3 * kept);
    }
    diag.warn_once("duplicate-emitters",
                   std::to_string(dropped) +
                       " emissive triangle(s) repeat another exactly (same corners and material); "
                       "the copies are dropped so that each surface emits once");
}

}  // namespace

void warn_morph_targets(Diagnostics& diag) {
    diag.warn_once("morph", "morph targets are not supported; base geometry used");
}

GeometryImporter::GeometryImporter(const tinygltf::Model& model, Diagnostics& diag,
                                   MaterialTable& materials, Scene& scene)
    : model_(model), diag_(diag), materials_(materials), scene_(scene) {}

void GeometryImporter::add_primitive(const tinygltf::Primitive& primitive,
                                     const std::string& element, const glm::dmat4& world,
                                     const std::string& node_element) {
    if (!primitive.targets.empty()) warn_morph_targets(diag_);
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
    const std::vector<glm::dvec3> local_positions =
        read_positions(model_, position->second, element, diag_);
    std::vector<glm::dvec3> positions(local_positions.size());
    for (size_t v = 0; v < positions.size(); ++v) {
        const glm::dvec3 p = glm::dvec3(world * glm::dvec4(local_positions[v], 1.0));
        if (!is_finite(p) || glm::any(glm::greaterThan(glm::abs(p), glm::dvec3(kMaxCoordinate)))) {
            diag_.fail(node_element, "transformed position of " + element +
                                         " is not finite or exceeds 1e30 in magnitude");
        }
        max_coordinate_ = std::max(max_coordinate_, max_component(glm::abs(p)));
        positions[v] = p;
    }
    std::vector<uint32_t> ids(positions.size());
    if (primitive.indices != -1) {
        ids = read_indices(model_, primitive.indices, positions.size(), element, diag_);
    } else {
        for (size_t v = 0; v < ids.size(); ++v) ids[v] = static_cast<uint32_t>(v);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && ids.size() % 3 != 0) {
        diag_.fail(element, std::to_string(ids.size()) +
                                (primitive.indices != -1 ? " indices" : " vertices") +
                                " are not a multiple of 3 (mode TRIANGLES)");
    }
    // A strip or fan of fewer than 3 is as malformed as TRIANGLES of a count not a multiple of 3
    // (glTF 2.0 "Meshes": strips and fans make count − 2 triangles).
    if (mode != TINYGLTF_MODE_TRIANGLES && ids.size() < 3) {
        diag_.fail(
            element,
            std::to_string(ids.size()) + (primitive.indices != -1 ? " indices" : " vertices") +
                " are fewer than one triangle's 3 (mode " +
                (mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "TRIANGLE_STRIP" : "TRIANGLE_FAN") + ")");
    }
    const std::vector<uint32_t> corners = triangle_list(mode, ids);
    const size_t triangles = corners.size() / 3;
    if (scene_.triangle_count() + triangles > kMaxTriangles) {
        diag_.fail("more than " + std::to_string(kMaxTriangles) + " triangles");
    }

    // A mirroring transform turns counter-clockwise into clockwise: swap two corners so the
    // front face stays the one the file means (and with them their attributes).
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
    const std::array<size_t, 3> corner_order =
        mirrored ? std::array<size_t, 3>{0, 2, 1} : std::array<size_t, 3>{0, 1, 2};
    // The material as this primitive sees it: textures on a TEXCOORD_n it lacks left out.
    uint32_t texcoord_sets = 0;
    for (uint32_t n = 0; n < 2; ++n)
        texcoord_sets |= uint32_t(primitive.attributes.count("TEXCOORD_" + std::to_string(n))) << n;
    std::string left_out;
    const uint32_t material = materials_.slot_for_texcoords(
        materials_.slot(primitive.material, element), texcoord_sets, left_out);
    if (!left_out.empty()) note_left_out_textures(primitive.material, element, left_out);
    const Material& surface = scene_.materials[material];
    const double Le_luminance = luminance(surface.emission);

    // The corners' texture attributes, once any primitive's material reads them.
    AttributeNeeds needs = attribute_needs(model_, primitive.material);
    if (needs.normal_texcoord >= 0 && !surface.normal_texture.used()) needs.normal_texcoord = -1;
    if (needs.texcoords && triangles > 0 && !corner_attributes_) {
        start_corner_attributes(scene_);
        corner_attributes_ = true;
    }
    CornerAttributes attributes;
    if (needs.texcoords && corner_attributes_) {
        attributes = read_corner_attributes(model_, primitive, needs, local_positions, corners,
                                            world, element, diag_);
    }
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
        for (size_t k : corner_order) {
            scene_.positions.push_back(glm::vec3(positions[corners[3 * t + k]]));
            if (corner_attributes_) append_corner_attributes(scene_, attributes, 3 * t + k);
        }
        scene_.triangle_material.push_back(material);
    }
}

void GeometryImporter::note_left_out_textures(int material_index, const std::string& element,
                                              const std::string& left_out) {
    // Instances of one primitive count once.
    if (!left_out_primitives_.insert(element).second) return;
    if (left_out_primitives_.size() > 1) return;
    std::string material = element_name("material", size_t(material_index));
    const std::string& name = model_.materials[size_t(material_index)].name;
    if (!name.empty()) material += " (\"" + name + "\")";
    left_out_first_ = element + ": lacks the texture coordinates that " + material + " reads for " +
                      left_out +
                      "; ignored there, the factors alone apply (glTF 2.0 \"Texture Data\": a "
                      "primitive MUST have them)";
}

void GeometryImporter::finish() {
    if (!left_out_primitives_.empty()) {
        const size_t others = left_out_primitives_.size() - 1;
        diag_.warn_once(
            "texcoord-missing",
            left_out_first_ +
                (others ? "; the same on " + std::to_string(others) + " more primitive(s)" : ""));
    }
    // Light selection divides by shares of the total: it must be a float too.
    if (!(total_power_ <= 0.5 * std::numeric_limits<float>::max())) {
        diag_.fail("the emitters' summed power " + format_number(total_power_) +
                   " overflows single precision (too many or too bright emitters)");
    }
    merge_duplicate_emitters(scene_, diag_);
    if (max_coordinate_ > kWarnCoordinate) {
        diag_.warn_once("coordinates", "coordinates up to " + format_number(max_coordinate_) +
                                           " exceed " + format_number(kWarnCoordinate) +
                                           ": float traversal may lose triangles");
    }
}

}  // namespace mcrt::gltf
