// Texture lookups as kernels/textures.cl does them, operation for operation (no fused
// multiply-add: GCC contracts only for targets that have one, and x86-64's default has none).
#include "scene/texture_lookup.h"

#include <algorithm>
#include <cmath>

namespace mcrt {

namespace {

int wrap_texel(int i, int n, TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::ClampToEdge: return std::clamp(i, 0, n - 1);
        case TextureWrap::MirroredRepeat: {
            const int m = ((i % (2 * n)) + 2 * n) % (2 * n);
            return m < n ? m : 2 * n - 1 - m;
        }
        case TextureWrap::Repeat: break;
    }
    return ((i % n) + n) % n;
}

float bounded_texel_coordinate(float x) {
    return std::isnan(x) ? 0.0f : std::clamp(x, -16777216.0f, 16777216.0f);
}

glm::vec4 texel_value(const TextureImage& image, int i, int j, bool srgb) {
    const uint8_t* t = &image.rgba[(size_t(j) * image.width + size_t(i)) * 4];
    auto colour = [&](uint8_t c) { return srgb ? srgb_table()[c] : float(c) / 255.0f; };
    return {colour(t[0]), colour(t[1]), colour(t[2]), float(t[3]) / 255.0f};
}

}  // namespace

float srgb_to_linear(uint8_t value) {
    const double c = double(value) / 255.0;
    return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

const std::array<float, 256>& srgb_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int c = 0; c < 256; ++c) t[size_t(c)] = srgb_to_linear(uint8_t(c));
        return t;
    }();
    return table;
}

glm::vec4 texture_lookup(const TextureImage& image, const TextureRef& ref, glm::vec2 st) {
    const float u = (ref.row_u.x * st.x + ref.row_u.y * st.y) + ref.row_u.z;
    const float v = (ref.row_v.x * st.x + ref.row_v.y * st.y) + ref.row_v.z;
    const int w = int(image.width), h = int(image.height);
    if (!ref.linear) {
        const int i = int(std::floor(bounded_texel_coordinate(u * float(w))));
        const int j = int(std::floor(bounded_texel_coordinate(v * float(h))));
        return texel_value(image, wrap_texel(i, w, ref.wrap_s), wrap_texel(j, h, ref.wrap_t),
                           ref.srgb);
    }
    const float x = bounded_texel_coordinate(u * float(w) - 0.5f);
    const float y = bounded_texel_coordinate(v * float(h) - 0.5f);
    const float x0 = std::floor(x), y0 = std::floor(y);
    const float fx = x - x0, fy = y - y0;
    const int i0 = wrap_texel(int(x0), w, ref.wrap_s), i1 = wrap_texel(int(x0) + 1, w, ref.wrap_s);
    const int j0 = wrap_texel(int(y0), h, ref.wrap_t), j1 = wrap_texel(int(y0) + 1, h, ref.wrap_t);
    const glm::vec4 c00 = texel_value(image, i0, j0, ref.srgb);
    const glm::vec4 c10 = texel_value(image, i1, j0, ref.srgb);
    const glm::vec4 c01 = texel_value(image, i0, j1, ref.srgb);
    const glm::vec4 c11 = texel_value(image, i1, j1, ref.srgb);
    return ((1.0f - fx) * c00 + fx * c10) * (1.0f - fy) + ((1.0f - fx) * c01 + fx * c11) * fy;
}

}  // namespace mcrt
