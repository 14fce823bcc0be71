// 8-bit sRGB PNG preview of an Image (DESIGN.md "Outputs").
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "image/image.h"

namespace mcrt {

namespace {

// sRGB OETF, the exact piecewise curve of IEC 61966-2-1:1999 (not a 2.2 power law).
double srgb_encode(double linear) {
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// Linear value to 8-bit code: NaN shows as black, out-of-range values clamp.
uint8_t to_8bit(double linear) {
    if (std::isnan(linear)) return 0;
    double encoded = srgb_encode(std::clamp(linear, 0.0, 1.0));
    return uint8_t(std::lround(std::clamp(encoded, 0.0, 1.0) * 255.0));
}

}  // namespace

void write_png_to(const std::string& file, const std::string& path, const Image& image,
                  float exposure) {
    const size_t floats = 3 * size_t(image.width) * size_t(image.height);
    if (image.width <= 0 || image.height <= 0 || image.rgb.size() != floats) {
        throw RuntimeError(path + ": image of " + std::to_string(image.width) + "x" +
                           std::to_string(image.height) +
                           " pixels is empty or its arrays have the wrong size");
    }
    const double scale = std::exp2(double(exposure));
    std::vector<uint8_t> pixels(floats);
    for (size_t i = 0; i < floats; ++i) pixels[i] = to_8bit(scale * image.rgb[i]);

    // Encode in memory: stbi_write_png ignores fwrite/fclose errors (stb_image_write.h v1.16),
    // which would let a full disk leave a truncated PNG in place.
    std::vector<char> encoded;
    auto append = [](void* context, void* data, int size) {
        auto& out = *static_cast<std::vector<char>*>(context);
        out.insert(out.end(), static_cast<const char*>(data),
                   static_cast<const char*>(data) + size);
    };
    // Row 0 is the top in both Image and PNG, so no flip.
    if (!stbi_write_png_to_func(append, &encoded, image.width, image.height, 3, pixels.data(),
                                3 * image.width)) {
        throw RuntimeError(path + ": cannot encode PNG");
    }

    errno = 0;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(encoded.data(), std::streamsize(encoded.size()));
    out.close();
    if (out.fail()) {
        throw RuntimeError(path + ": cannot write PNG: " + std::strerror(errno ? errno : EIO));
    }
}

void write_png(const std::string& path, const Image& image, float exposure) {
    write_atomically(path, [&](const std::string& temporary) {
        write_png_to(temporary, path, image, exposure);
    });
}

}  // namespace mcrt
