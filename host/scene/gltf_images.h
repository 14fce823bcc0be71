// The glTF images that texture slots use, decoded to 8-bit RGBA (glTF 2.0 "Images"): PNG and
// JPEG only, each checked from its header against the limits before a texel is allocated, each
// decoded once, on several threads.
#pragma once

#include <tiny_gltf.h>

#include <string>
#include <vector>

#include "scene/gltf_diagnostics.h"
#include "scene/scene.h"

namespace mcrt::gltf {

// The glTF images `sources` (indices into model.images) decoded in that order: element k of the
// result is image sources[k]. The encoded bytes are what gltf_parse.cpp kept of a uri (its file or
// data URI) or the image's bufferView, checked to lie inside its buffer. An image that is not PNG
// or JPEG (KTX2, WebP and DDS are named by the extension that brings them), that is truncated or
// corrupt, or whose header exceeds kMaxImageSide, or with the others kMaxImageTexels, fails naming
// it; with several failures the first in `sources` order is reported, whatever the threads did.
// `threads` 0: one per core, at most 8.
std::vector<TextureImage> decode_images(const tinygltf::Model& model,
                                        const std::vector<int>& sources, const Diagnostics& diag,
                                        unsigned threads = 0);

}  // namespace mcrt::gltf
