// Texture lookup in float, operation for operation as the kernels do it (texture_lookup.h).
#include "scene/texture_lookup.h"

#include <cmath>

namespace mcrt {

namespace {

// Texel coordinates beyond ±2^24 no longer hold a fraction in float; a NaN reads texel 0.
float clamp_texel_coordinate(float x) {
    const float limit = 16777216.0f;  // 2^24
    if (!(x == x)) return 0.0f;
    return x < -limit ? -limit : (x > limit ? limit : x);
}

}  // namespace

float srgb_to_linear(uint8_t c) {
    const double v = double(c) / 255.0;
    return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

const std::array<float, 256>& srgb_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int c = 0; c < 256; ++c) t[size_t(c)] = srgb_to_linear(uint8_t(c));
        return t;
    }();
    return table;
}

int32_t wrap_texel_index(int32_t i, int32_t n, TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::Repeat:
            return ((i % n) + n) % n;
        case TextureWrap::ClampToEdge:
            return i < 0 ? 0 : (i > n - 1 ? n - 1 : i);
        case TextureWrap::MirroredRepeat: {
            const int32_t m = ((i % (2 * n)) + 2 * n) % (2 * n);
            return m < n ? m : 2 * n - 1 - m;
        }
    }
    return 0;
}

glm::vec4 fetch_texel(const TextureImage& image, int32_t i, int32_t j, bool srgb) {
    const uint8_t* t = &image.rgba[(size_t(j) * image.width + size_t(i)) * 4];
    const std::array<float, 256>& table = srgb_table();
    if (srgb) return glm::vec4(table[t[0]], table[t[1]], table[t[2]], float(t[3]) / 255.0f);
    return glm::vec4(float(t[0]) / 255.0f, float(t[1]) / 255.0f, float(t[2]) / 255.0f,
                     float(t[3]) / 255.0f);
}

glm::vec4 texture_lookup(const TextureImage& image, const TextureRef& ref, glm::vec2 uv) {
    // KHR_texture_transform: (u', v') = M (u, v, 1).
    const float u = ref.row_u.x * uv.x + ref.row_u.y * uv.y + ref.row_u.z;
    const float v = ref.row_v.x * uv.x + ref.row_v.y * uv.y + ref.row_v.z;
    const int32_t w = int32_t(image.width), h = int32_t(image.height);
    const float fw = float(image.width), fh = float(image.height);

    if (!ref.linear) {
        // NEAREST: the texel whose square holds (u'W, v'H).
        const int32_t i = int32_t(std::floor(clamp_texel_coordinate(u * fw)));
        const int32_t j = int32_t(std::floor(clamp_texel_coordinate(v * fh)));
        return fetch_texel(image, wrap_texel_index(i, w, ref.wrap_s),
                           wrap_texel_index(j, h, ref.wrap_t), ref.srgb);
    }

    // LINEAR: texel centres lie at half-integers; weigh the four about the point.
    const float x = clamp_texel_coordinate(u * fw - 0.5f);
    const float y = clamp_texel_coordinate(v * fh - 0.5f);
    const float x0 = std::floor(x), y0 = std::floor(y);
    const float fx = x - x0, fy = y - y0;
    const int32_t i0 = int32_t(x0), j0 = int32_t(y0);
    const int32_t ia = wrap_texel_index(i0, w, ref.wrap_s);
    const int32_t ib = wrap_texel_index(i0 + 1, w, ref.wrap_s);
    const int32_t ja = wrap_texel_index(j0, h, ref.wrap_t);
    const int32_t jb = wrap_texel_index(j0 + 1, h, ref.wrap_t);
    const glm::vec4 c00 = fetch_texel(image, ia, ja, ref.srgb);
    const glm::vec4 c10 = fetch_texel(image, ib, ja, ref.srgb);
    const glm::vec4 c01 = fetch_texel(image, ia, jb, ref.srgb);
    const glm::vec4 c11 = fetch_texel(image, ib, jb, ref.srgb);
    const glm::vec4 top = (1.0f - fx) * c00 + fx * c10;
    const glm::vec4 bottom = (1.0f - fx) * c01 + fx * c11;
    return top * (1.0f - fy) + bottom * fy;
}

}  // namespace mcrt
