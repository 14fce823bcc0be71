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
#include <utility>
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

    // The slot of the material at `slot` as a primitive with the TEXCOORD_n sets `texcoord_sets`
    // (bit n) sees it: glTF 2.0 "Texture Data" says a primitive MUST have the set a texture
    // reads for the material to apply, so a texture reading a set the primitive lacks is left
    // out, in a copy of the material made once per slot and set of textures left out (the
    // factors alone apply: texel (0, 0) would be read everywhere). `left_out` gets their names
    // and sets, "baseColorTexture (TEXCOORD_1)", empty when none is.
    uint32_t slot_for_texcoords(uint32_t slot, uint32_t texcoord_sets, std::string& left_out);

  private:
    Material convert(int material_index, const std::string& referrer);

    const tinygltf::Model& model_;
    Diagnostics& diag_;
    TextureTable& textures_;
    std::vector<Material>& materials_;
    std::map<int, uint32_t> slots_;  // glTF material index (−1: default) → slot
    // (slot, texture slots left out as bits of kTextureSlots) → slot of the copy
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> copies_;
};

}  // namespace mcrt::gltf
