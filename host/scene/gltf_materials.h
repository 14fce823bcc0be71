// The glTF materials a scene uses, converted to mcrt's Material (DESIGN.md "Radiometric
// contract"): factors, alpha mode and the base colour, metallic-roughness, normal and emissive
// texture slots (their images decoded once the scene is walked, gltf_images.h), index of
// refraction, transmission and volume factors. Occlusion and transmission textures are warned
// about and ignored.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scene/gltf_diagnostics.h"
#include "scene/gltf_textures.h"
#include "scene/scene.h"

namespace mcrt::gltf {

// Each glTF material converted once, when a primitive first uses it: slots follow first use, and
// a material's errors name the primitive that first refers to it.
class MaterialTable {
  public:
    // Converted materials are appended to `materials` (the Scene's); their texture slots are
    // read through `textures`, which gives the images they use their Scene::images slots.
    MaterialTable(const tinygltf::Model& model, Diagnostics& diag, TextureTable& textures,
                  std::vector<Material>& materials);

    // The slot in `materials` of glTF material `material_index` (−1: the default material);
    // `referrer` names the element that refers to it.
    uint32_t slot(int material_index, const std::string& referrer);

  private:
    Material convert(int material_index, const std::string& referrer);

    const tinygltf::Model& model_;
    Diagnostics& diag_;
    TextureTable& textures_;
    std::vector<Material>& materials_;
    std::map<int, uint32_t> slots_;  // glTF material index (−1: default) → slot
};

}  // namespace mcrt::gltf
