// The host twin of the kernels' texture lookup (host/scene/texture_lookup.h): sRGB decoding,
// each wrap mode, nearest and bilinear filtering, the KHR_texture_transform rows and the order of
// their float operations, and the clamp of texel coordinates.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "scene/texture_lookup.h"

using namespace mcrt;

namespace {

// An image whose texel (i, j) is (r, g, b, a) = (10 i + 1, 10 j + 2, 3, 200 + i): each texel told
// apart by its red and green.
TextureImage numbered_image(uint32_t width, uint32_t height) {
    TextureImage image;
    image.name = "numbered";
    image.width = width;
    image.height = height;
    for (uint32_t j = 0; j < height; ++j) {
        for (uint32_t i = 0; i < width; ++i) {
            image.rgba.insert(image.rgba.end(),
                              {uint8_t(10 * i + 1), uint8_t(10 * j + 2), 3, uint8_t(200 + i)});
        }
    }
    return image;
}

// Which texel a NEAREST lookup of `numbered_image` read, from its linear red and green.
glm::ivec2 texel_read(const glm::vec4& value) {
    return glm::ivec2(int(std::lround(value.r * 255.0f - 1.0f)) / 10,
                      int(std::lround(value.g * 255.0f - 2.0f)) / 10);
}

TextureRef nearest(TextureWrap wrap_s = TextureWrap::Repeat,
                   TextureWrap wrap_t = TextureWrap::Repeat) {
    TextureRef ref;
    ref.image = 0;
    ref.linear = false;
    ref.wrap_s = wrap_s;
    ref.wrap_t = wrap_t;
    return ref;
}

}  // namespace

TEST_CASE("sRGB decoding is IEC 61966-2-1's, rounded once to float", "[textures]") {
    CHECK(srgb_to_linear(0) == 0.0f);
    CHECK(srgb_to_linear(255) == 1.0f);
    CHECK(srgb_to_linear(128) == 0.2158605f);
    // Either side of the threshold 0.04045: 10/255 is on the linear segment, 11/255 on the curve.
    CHECK(srgb_to_linear(10) == float(10.0 / 255.0 / 12.92));
    CHECK(srgb_to_linear(11) == Approx(0.0033465358).epsilon(1e-7));
    CHECK(srgb_to_linear(64) == Approx(0.0512694584).epsilon(1e-7));
    CHECK(srgb_to_linear(200) == Approx(0.5775804404).epsilon(1e-7));
    const std::array<float, 256>& table = srgb_table();
    for (int c = 0; c < 256; ++c) {
        CHECK(table[size_t(c)] == srgb_to_linear(uint8_t(c)));
        if (c > 0) CHECK(table[size_t(c)] > table[size_t(c - 1)]);
    }
}

TEST_CASE("texel indices wrap per mode", "[textures]") {
    const int32_t n = 4;
    SECTION("REPEAT") {
        const int32_t expected[][2] = {{0, 0}, {3, 3}, {4, 0}, {5, 1}, {-1, 3}, {-4, 0}, {-5, 3}};
        for (const auto& e : expected)
            CHECK(wrap_texel_index(e[0], n, TextureWrap::Repeat) == e[1]);
    }
    SECTION("CLAMP_TO_EDGE") {
        const int32_t expected[][2] = {{0, 0}, {3, 3}, {4, 3}, {100, 3}, {-1, 0}, {-100, 0}};
        for (const auto& e : expected)
            CHECK(wrap_texel_index(e[0], n, TextureWrap::ClampToEdge) == e[1]);
    }
    SECTION("MIRRORED_REPEAT") {
        const int32_t expected[][2] = {{0, 0},  {3, 3},  {4, 3},  {5, 2},  {7, 0}, {8, 0},
                                       {-1, 0}, {-2, 1}, {-4, 3}, {-5, 3}, {-8, 0}};
        for (const auto& e : expected)
            CHECK(wrap_texel_index(e[0], n, TextureWrap::MirroredRepeat) == e[1]);
    }
    SECTION("the extremes of the clamped coordinates") {
        for (TextureWrap wrap :
             {TextureWrap::Repeat, TextureWrap::ClampToEdge, TextureWrap::MirroredRepeat}) {
            for (int32_t i : {-(1 << 24), (1 << 24) + 1}) {
                const int32_t w = wrap_texel_index(i, 16384, wrap);
                CHECK(w >= 0);
                CHECK(w < 16384);
            }
        }
    }
}

TEST_CASE("texels decode before filtering: sRGB by the table, linear and alpha by / 255",
          "[textures]") {
    TextureImage image;
    image.width = image.height = 1;
    for (int c = 0; c < 256; ++c) {
        image.rgba = {uint8_t(c), uint8_t(c), uint8_t(c), uint8_t(c)};
        const glm::vec4 srgb = fetch_texel(image, 0, 0, true);
        const glm::vec4 linear = fetch_texel(image, 0, 0, false);
        CHECK(srgb.r == srgb_table()[size_t(c)]);
        CHECK(srgb.a == float(c) / 255.0f);  // alpha is never sRGB-encoded
        CHECK(linear.r == float(c) / 255.0f);
        CHECK(linear.a == float(c) / 255.0f);
    }
}

TEST_CASE("NEAREST reads the texel whose square holds the point, wrapped per axis", "[textures]") {
    const TextureImage image = numbered_image(4, 2);
    const TextureRef repeat = nearest();
    CHECK(texel_read(texture_lookup(image, repeat, {0.1f, 0.2f})) == glm::ivec2(0, 0));
    CHECK(texel_read(texture_lookup(image, repeat, {0.26f, 0.51f})) == glm::ivec2(1, 1));
    CHECK(texel_read(texture_lookup(image, repeat, {0.99f, 0.99f})) == glm::ivec2(3, 1));
    // u = 1 is texel 4: the first again, the last when clamped or mirrored.
    CHECK(texel_read(texture_lookup(image, repeat, {1.0f, 0.0f})) == glm::ivec2(0, 0));
    CHECK(texel_read(texture_lookup(image, nearest(TextureWrap::ClampToEdge), {1.0f, 0.0f})) ==
          glm::ivec2(3, 0));
    CHECK(texel_read(texture_lookup(image, nearest(TextureWrap::MirroredRepeat), {1.0f, 0.0f})) ==
          glm::ivec2(3, 0));
    // Below 0: the last texel repeated, the first clamped or mirrored; t wraps on its own.
    CHECK(texel_read(texture_lookup(image, repeat, {-0.1f, -0.1f})) == glm::ivec2(3, 1));
    const TextureRef mixed = nearest(TextureWrap::ClampToEdge, TextureWrap::MirroredRepeat);
    CHECK(texel_read(texture_lookup(image, mixed, {-0.1f, -0.1f})) == glm::ivec2(0, 0));
    CHECK(texel_read(texture_lookup(image, mixed, {1.6f, 1.6f})) == glm::ivec2(3, 0));
    // Row 0 is the image's top row, where v = 0 lies.
    CHECK(texture_lookup(image, repeat, {0.0f, 0.0f}) == fetch_texel(image, 0, 0, false));
    CHECK(texture_lookup(image, repeat, {0.0f, 0.9f}) == fetch_texel(image, 0, 1, false));
}

TEST_CASE("NaN and huge texture coordinates read a texel, never outside the image", "[textures]") {
    const TextureImage image = numbered_image(3, 3);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    CHECK(texel_read(texture_lookup(image, nearest(), {nan, nan})) == glm::ivec2(0, 0));
    // Clamped to ±2^24 texels: 2^24 mod 3 = 1, −2^24 mod 3 = 2.
    CHECK(texel_read(texture_lookup(image, nearest(), {1e30f, 1e30f})) == glm::ivec2(1, 1));
    CHECK(texel_read(texture_lookup(image, nearest(), {-1e30f, -1e30f})) == glm::ivec2(2, 2));
    const TextureRef clamped = nearest(TextureWrap::ClampToEdge, TextureWrap::ClampToEdge);
    CHECK(texel_read(texture_lookup(image, clamped, {1e30f, -1e30f})) == glm::ivec2(2, 0));
    // An infinite u clamps like a huge one, and is NaN in the other row (0 × ∞): texel 0 there.
    CHECK(texel_read(texture_lookup(image, nearest(), {inf, 0.5f})) == glm::ivec2(1, 0));
    CHECK(texel_read(texture_lookup(image, nearest(), {0.5f, -inf})) == glm::ivec2(0, 2));
    TextureRef linear = nearest();
    linear.linear = true;
    for (float u : {nan, inf, -inf, 1e30f, -1e30f}) {
        const glm::vec4 v = texture_lookup(image, linear, {u, 0.5f});
        CHECK(std::isfinite(v.r));
        CHECK(v.r >= 0.0f);
        CHECK(v.r <= 1.0f);
    }
}

TEST_CASE("LINEAR weighs the four texels about the point after decoding them", "[textures]") {
    // TextureLinearInterpolationTest's 2×1 image: black to full green, sRGB-encoded.
    TextureImage ramp;
    ramp.width = 2;
    ramp.height = 1;
    ramp.rgba = {0, 0, 0, 255, 0, 255, 0, 255};
    TextureRef ref;
    ref.image = 0;
    ref.srgb = true;
    ref.wrap_s = ref.wrap_t = TextureWrap::ClampToEdge;
    // Texel centres (u = 1/4, 3/4) read their texel exactly; halfway the mean of the decoded
    // values, 0.5, not the decoded mean of the codes (0.2158605 for 128).
    CHECK(texture_lookup(ramp, ref, {0.25f, 0.5f}).g == 0.0f);
    CHECK(texture_lookup(ramp, ref, {0.75f, 0.5f}).g == 1.0f);
    CHECK(texture_lookup(ramp, ref, {0.5f, 0.5f}).g == 0.5f);
    CHECK(texture_lookup(ramp, ref, {0.375f, 0.5f}).g == 0.25f);
    CHECK(texture_lookup(ramp, ref, {0.5f, 0.5f}).a == 1.0f);
    // Clamped, the edge reads its texel alone; repeated, it blends with the other side.
    CHECK(texture_lookup(ramp, ref, {0.0f, 0.5f}).g == 0.0f);
    ref.wrap_s = TextureWrap::Repeat;
    CHECK(texture_lookup(ramp, ref, {0.0f, 0.5f}).g == 0.5f);
    ref.wrap_s = TextureWrap::MirroredRepeat;
    CHECK(texture_lookup(ramp, ref, {0.0f, 0.5f}).g == 0.0f);

    SECTION("the weights and their order are the contract's, in float") {
        const TextureImage image = numbered_image(3, 2);
        TextureRef linear;
        linear.image = 0;
        for (const glm::vec2 uv : {glm::vec2(0.3f, 0.7f), glm::vec2(0.91f, 0.13f),
                                   glm::vec2(-0.37f, 2.2f), glm::vec2(0.5f, 0.25f)}) {
            const float x = uv.x * 3.0f - 0.5f, y = uv.y * 2.0f - 0.5f;
            const float fx = x - std::floor(x), fy = y - std::floor(y);
            const int i0 = int(std::floor(x)), j0 = int(std::floor(y));
            auto c = [&](int i, int j) {
                return fetch_texel(image, wrap_texel_index(i, 3, TextureWrap::Repeat),
                                   wrap_texel_index(j, 2, TextureWrap::Repeat), false);
            };
            const glm::vec4 expected =
                ((1.0f - fx) * c(i0, j0) + fx * c(i0 + 1, j0)) * (1.0f - fy) +
                ((1.0f - fx) * c(i0, j0 + 1) + fx * c(i0 + 1, j0 + 1)) * fy;
            CHECK(texture_lookup(image, linear, uv) == expected);
        }
    }
}

TEST_CASE("the transform rows map (u, v, 1), each as row.x·u + row.y·v + row.z in that order",
          "[textures]") {
    const TextureImage image = numbered_image(2, 2);
    SECTION("a swap of u and v with an offset") {
        TextureRef ref = nearest();
        ref.row_u = {0.0f, 1.0f, 0.5f};
        ref.row_v = {1.0f, 0.0f, 0.0f};
        // (u, v) = (0.1, 0.2) → (0.7, 0.1): texel (1, 0).
        CHECK(texel_read(texture_lookup(image, ref, {0.1f, 0.2f})) == glm::ivec2(1, 0));
        CHECK(texel_read(texture_lookup(image, ref, {0.7f, 0.2f})) == glm::ivec2(1, 1));
    }
    SECTION("left to right: (a u + b v) + c, not a u + (b v + c)") {
        // a u = 1/2 + 2^-24, b v = c = −2^-25. Left to right: 1/2 + 2^-25 rounds to 1/2 (ties to
        // even), then 1/2 − 2^-25 lies in texel 0 of 2. The other order gives exactly 1/2, texel 1.
        TextureRef ref = nearest();
        ref.row_u = {0.5f + std::ldexp(1.0f, -24), -std::ldexp(1.0f, -25), -std::ldexp(1.0f, -25)};
        CHECK(texel_read(texture_lookup(image, ref, {1.0f, 1.0f})).x == 0);
        ref.row_u = {0.5f + std::ldexp(1.0f, -24), 0.0f, -std::ldexp(1.0f, -24)};
        CHECK(texel_read(texture_lookup(image, ref, {1.0f, 1.0f})).x == 1);
    }
}
