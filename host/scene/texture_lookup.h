// The kernels' texture lookup on the host (kernels/textures.cl), with the same arithmetic: what
// emitters' powers are computed from, and what tests compare the device against.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace mcrt {

// 8-bit sRGB-encoded value → linear (IEC 61966-2-1), computed in double, rounded to float.
float srgb_to_linear(uint8_t value);

// srgb_to_linear of every 8-bit value: the table the kernels decode sRGB texels with.
const std::array<float, 256>& srgb_table();

// The texture of `ref` (an image of `image`) at texture coordinates uv of its set (TEXCOORD_0 or
// _1, as ref.texcoord says; the caller passes that set): KHR_texture_transform, wrap, NEAREST or
// bilinear between texel centres, each texel decoded to linear first (colour by ref.srgb, alpha
// linear).
glm::vec4 texture_lookup(const TextureImage& image, const TextureRef& ref, glm::vec2 uv);

}  // namespace mcrt
