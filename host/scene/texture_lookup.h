// The host's twin of the kernels' texture lookup: the same float operations in the same order
// (no fused multiply-add: this file is compiled with -ffp-contract=off), so that tests can compare
// a device's texel reads with it bit for bit, and the sRGB decoding table the kernels receive.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>

#include "scene/scene.h"

namespace mcrt {

// IEC 61966-2-1's sRGB decoding of an 8-bit value v = c/255: v/12.92 for v ≤ 0.04045, else
// ((v + 0.055)/1.055)^2.4; computed in double, rounded once to float.
float srgb_to_linear(uint8_t c);

// srgb_to_linear of every 8-bit value: the table the host hands the kernels.
const std::array<float, 256>& srgb_table();

// Integer texel index `i` wrapped into [0, n) along one axis (glTF 2.0 "Samplers").
int32_t wrap_texel_index(int32_t i, int32_t n, TextureWrap wrap);

// The texel (i, j) of `image` (already wrapped) as floats: RGB through srgb_table when `srgb`,
// else c / 255; alpha always a / 255.
glm::vec4 fetch_texel(const TextureImage& image, int32_t i, int32_t j, bool srgb);

// The value of slot `ref` of `image` at texture coordinates `uv`:
// uv' = (row_u · (u, v, 1), row_v · (u, v, 1)), each as row.x·u + row.y·v + row.z in that order;
// NEAREST reads texel (floor(u'W), floor(v'H)); LINEAR weighs the four texels about
// (u'W − 0.5, v'H − 0.5), decoded before they are weighed. Texel coordinates are clamped to
// [−2^24, 2^24] (NaN → 0) before floor, then wrapped per axis. `image` must have texels.
glm::vec4 texture_lookup(const TextureImage& image, const TextureRef& ref, glm::vec2 uv);

}  // namespace mcrt
