// Texture coordinates, normals and tangents per corner ("Meshes", attribute table; "Materials";
// "Transformations"), read in the primitive's frame and carried into the world.
#include "scene/gltf_attributes.h"

#include <cmath>

#include "scene/gltf_accessors.h"
#include "scene/tangents.h"

namespace mcrt::gltf {

namespace {

// The set a textureInfo reads: KHR_texture_transform's texCoord overrides its own.
int texcoord_set(int tex_coord, const tinygltf::ExtensionMap& extensions) {
    const auto transform = extensions.find("KHR_texture_transform");
    if (transform != extensions.end() && transform->second.Has("texCoord") &&
        transform->second.Get("texCoord").IsNumber()) {
        return transform->second.Get("texCoord").GetNumberAsInt();
    }
    return tex_coord;
}

// TEXCOORD_`set` per vertex, zeros when the primitive has none.
std::vector<glm::dvec2> read_texcoord_set(const tinygltf::Model& model,
                                          const tinygltf::Primitive& primitive, int set,
                                          size_t vertex_count, const std::string& element,
                                          const Diagnostics& diag) {
    const auto attribute = primitive.attributes.find("TEXCOORD_" + std::to_string(set));
    if (attribute == primitive.attributes.end()) {
        return std::vector<glm::dvec2>(vertex_count, glm::dvec2(0.0));
    }
    return read_texcoords(model, attribute->second, vertex_count, attribute->first, element, diag);
}

bool not_zero(const glm::dvec3& v) { return glm::dot(v, v) > 0.0 && std::isfinite(glm::dot(v, v)); }

// The normal transform |det| · M⁻ᵀ of the linear part M, as its cofactor matrix: no division, so a
// singular transform yields zero (and the fallbacks) instead of infinities. The sign keeps normals
// on the front face, which the mirrored corner swap keeps too.
glm::dmat3 normal_matrix(const glm::dmat3& m) {
    const glm::dmat3 cofactor(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]),
                              glm::cross(m[0], m[1]));
    return glm::determinant(m) < 0.0 ? -cofactor : cofactor;
}

}  // namespace

AttributeNeeds attribute_needs(const tinygltf::Model& model, int material) {
    AttributeNeeds needs;
    if (material < 0) return needs;
    const tinygltf::Material& m = model.materials[static_cast<size_t>(material)];
    const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
    needs.texcoords = pbr.baseColorTexture.index >= 0 || pbr.metallicRoughnessTexture.index >= 0 ||
                      m.normalTexture.index >= 0 || m.emissiveTexture.index >= 0 ||
                      (!m.alphaMode.empty() && m.alphaMode != "OPAQUE");
    if (m.normalTexture.index >= 0) {
        needs.normal_texcoord = texcoord_set(m.normalTexture.texCoord, m.normalTexture.extensions);
    }
    return needs;
}

CornerAttributes read_corner_attributes(
    const tinygltf::Model& model, const tinygltf::Primitive& primitive, const AttributeNeeds& needs,
    const std::vector<glm::dvec3>& local_positions, const std::vector<uint32_t>& corners,
    const glm::dmat4& world, const std::string& element, const Diagnostics& diag) {
    const size_t vertex_count = local_positions.size();
    CornerAttributes out;

    // Texture coordinates of sets 0 and 1, per corner.
    const std::vector<glm::dvec2> uv0 =
        read_texcoord_set(model, primitive, 0, vertex_count, element, diag);
    const std::vector<glm::dvec2> uv1 =
        read_texcoord_set(model, primitive, 1, vertex_count, element, diag);
    out.texcoords.reserve(corners.size());
    for (uint32_t v : corners) out.texcoords.emplace_back(glm::dvec4(uv0[v], uv1[v]));
    if (needs.normal_texcoord < 0) return out;

    // Normals in the primitive's frame: NORMAL's, else flat; without NORMAL any TANGENT is
    // ignored ("Meshes": flat normals MUST be used and provided tangents ignored).
    const auto normal_attribute = primitive.attributes.find("NORMAL");
    const auto tangent_attribute = primitive.attributes.find("TANGENT");
    const bool has_normals = normal_attribute != primitive.attributes.end();
    const bool has_tangents = has_normals && tangent_attribute != primitive.attributes.end();
    std::vector<glm::dvec3> vertex_normals;
    if (has_normals) {
        vertex_normals = read_normals(model, normal_attribute->second, vertex_count, element, diag);
    }
    const size_t triangles = corners.size() / 3;
    std::vector<glm::dvec3> positions(corners.size()), faces(triangles), normals(corners.size());
    for (size_t t = 0; t < triangles; ++t) {
        for (size_t k = 0; k < 3; ++k) positions[3 * t + k] = local_positions[corners[3 * t + k]];
        const glm::dvec3 face = glm::cross(positions[3 * t + 1] - positions[3 * t],
                                           positions[3 * t + 2] - positions[3 * t]);
        faces[t] = not_zero(face) ? glm::normalize(face) : glm::dvec3(0.0);
        for (size_t k = 0; k < 3; ++k) {
            const glm::dvec3 n = has_normals ? vertex_normals[corners[3 * t + k]] : faces[t];
            normals[3 * t + k] = not_zero(n) ? glm::normalize(n) : faces[t];
        }
    }

    // Tangents in the primitive's frame: TANGENT's, else MikkTSpace's from the positions, the
    // normals and the normal texture's coordinates ("Meshes": tangents SHOULD be generated so).
    std::vector<glm::dvec4> generated;
    auto generate = [&] {
        if (!generated.empty()) return;
        std::vector<glm::dvec2> uv;
        if (needs.normal_texcoord == 0) {
            uv = uv0;
        } else if (needs.normal_texcoord == 1) {
            uv = uv1;
        } else {
            uv = read_texcoord_set(model, primitive, needs.normal_texcoord, vertex_count, element,
                                   diag);
        }
        std::vector<glm::dvec2> corner_uv(corners.size());
        for (size_t c = 0; c < corners.size(); ++c) corner_uv[c] = uv[corners[c]];
        generated = generate_tangents(positions, normals, corner_uv);
    };
    std::vector<glm::dvec4> tangents(corners.size());
    if (has_tangents) {
        const std::vector<glm::dvec4> vertex_tangents =
            read_tangents(model, tangent_attribute->second, vertex_count, element, diag);
        for (size_t c = 0; c < corners.size(); ++c) tangents[c] = vertex_tangents[corners[c]];
    } else {
        generate();
        tangents = generated;
    }

    // Into the world: normals by the inverse transpose, tangents by the linear part, both
    // renormalised; a mirroring transform flips the handedness. A zero result falls back to the
    // face normal, or to the generated tangent and then to any tangent of the normal.
    const glm::dmat3 linear(world);
    const glm::dmat3 normal_transform = normal_matrix(linear);
    const double handedness = glm::determinant(linear) < 0.0 ? -1.0 : 1.0;
    // Unusable: zero, or (within 1e-6 radians) along the normal, leaving no tangent plane.
    auto world_tangent = [&](const glm::dvec4& t, const glm::dvec3& n) {
        const glm::dvec3 w = linear * glm::dvec3(t);
        const bool usable = not_zero(w) && glm::length(glm::cross(n, glm::normalize(w))) > 1e-6;
        return usable ? glm::normalize(w) : glm::dvec3(0.0);
    };
    out.normals.reserve(corners.size());
    out.tangents.reserve(corners.size());
    for (size_t c = 0; c < corners.size(); ++c) {
        glm::dvec3 n = normal_transform * normals[c];
        if (!not_zero(n)) n = normal_transform * faces[c / 3];
        n = not_zero(n) ? glm::normalize(n) : glm::dvec3(0.0, 0.0, 1.0);
        glm::dvec4 local = tangents[c];
        glm::dvec3 t = world_tangent(local, n);
        if (!not_zero(t) && has_tangents) {
            generate();
            local = generated[c];
            t = world_tangent(local, n);
        }
        double w = (local.w < 0.0 ? -1.0 : 1.0) * handedness;
        if (!not_zero(t)) {
            t = any_tangent(n);
            w = 1.0;
        }
        out.normals.emplace_back(n);
        out.tangents.emplace_back(glm::dvec4(t, w));
    }
    return out;
}

}  // namespace mcrt::gltf
