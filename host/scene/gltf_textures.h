// A material's texture slots from glTF textureInfo (glTF 2.0 "Texture Data"): each texture's
// image, sampler and texture coordinate set, with KHR_texture_transform. The images the slots use
// get Scene::images slots in first-use order, so that each is decoded once (gltf_images.h).
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scene/gltf_diagnostics.h"
#include "scene/scene.h"

namespace mcrt::gltf {

class TextureTable {
  public:
    TextureTable(const tinygltf::Model& model, Diagnostics& diag);

    // The slot that textureInfo `info` (a tinygltf TextureInfo or NormalTextureInfo) describes,
    // `element` naming it ("material 2 baseColorTexture"); `srgb`: it holds sRGB-encoded colour.
    // Empty when there is no textureInfo (index −1) or its texture has no image (one warning).
    template <typename Info>
    TextureRef read(const Info& info, bool srgb, const std::string& element) {
        return read(info.index, info.texCoord, info.extensions, srgb, element);
    }

    // The same for a textureInfo inside an extension (a tinygltf::Value object, its integers
    // checked by check_gltf_types: index 0..INT_MAX, texCoord too).
    TextureRef read_value(const tinygltf::Value& info, bool srgb, const std::string& element);

    // The glTF image of each Scene::images slot, in slot order: what decode_images decodes.
    const std::vector<int>& image_sources() const { return sources_; }

  private:
    TextureRef read(int index, int texcoord, const tinygltf::ExtensionMap& extensions, bool srgb,
                    const std::string& element);
    int source_image(const tinygltf::Texture& texture, const std::string& texture_element);
    void read_sampler(int sampler_index, const std::string& texture_element, TextureRef& ref);
    int32_t image_slot(int image_index);

    const tinygltf::Model& model_;
    Diagnostics& diag_;
    std::map<int, int32_t> image_slots_;  // glTF image index → Scene::images slot
    std::vector<int> sources_;            // Scene::images slot → glTF image index
};

}  // namespace mcrt::gltf
