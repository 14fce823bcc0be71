// The triangles of a glTF model's mesh primitives, appended to mcrt's Scene in world space.
#pragma once

#include <tiny_gltf.h>

#include <glm/glm.hpp>
#include <set>
#include <string>

#include "scene/gltf_diagnostics.h"
#include "scene/gltf_materials.h"
#include "scene/scene.h"

namespace mcrt::gltf {

// Morph targets (a node's weights, a primitive's targets) are ignored: one warning for both.
void warn_morph_targets(Diagnostics& diag);

// Appends each primitive's triangles, with their material slots, to `scene`, and keeps what the
// whole scene is checked against once every primitive is in. Once a primitive's material reads
// textures, every corner also has its attributes (scene.h Scene::texcoords, normals, tangents).
class GeometryImporter {
  public:
    GeometryImporter(const tinygltf::Model& model, Diagnostics& diag, MaterialTable& materials,
                     Scene& scene);

    // Primitive `element` of a mesh that node `node_element` places with transform `world`:
    // TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN; points and lines are skipped with a warning.
    void add_primitive(const tinygltf::Primitive& primitive, const std::string& element,
                       const glm::dmat4& world, const std::string& node_element);

    // After the last primitive: the emitters' summed power must be a float, repeated emissive
    // triangles are dropped, and coordinates beyond kWarnCoordinate are warned about.
    void finish();

  private:
    // Primitive `element` lacks the TEXCOORD_n of its material's textures `left_out`: noted here,
    // warned about once in finish().
    void note_left_out_textures(int material_index, const std::string& element,
                                const std::string& left_out);

    const tinygltf::Model& model_;
    Diagnostics& diag_;
    MaterialTable& materials_;
    Scene& scene_;
    double total_power_ = 0.0;     // of every emissive triangle instance, in double
    double max_coordinate_ = 0.0;  // largest |component| of a world position
    // A textured primitive came: from then on every corner has attributes.
    bool corner_attributes_ = false;
    std::set<std::string> left_out_primitives_;  // primitives with textures left out
    std::string left_out_first_;                 // the first, as the warning names it
};

}  // namespace mcrt::gltf
