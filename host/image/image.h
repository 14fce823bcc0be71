// Float RGB images with per-pixel variance, and their EXR / PNG files.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace mcrt {

struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;       // 3 per pixel, row 0 at the top: the pixel means
    std::vector<float> variance;  // 3 per pixel: variance of the pixel mean
    double spp = 0;               // samples per pixel

    Image() = default;
    Image(int w, int h)
        : width(w), height(h), rgb(3 * size_t(w) * h), variance(3 * size_t(w) * h) {}
};

// EXR with float32 channels R, G, B, variance.R, variance.G, variance.B and a float header
// attribute `spp`; `attributes` become string header attributes. Written atomically.
void write_exr(const std::string& path, const Image& image,
               const std::map<std::string, std::string>& attributes = {});

// The same into `file`, opened and truncated (an OutputSet's temporary); messages name `path`.
void write_exr_to(const std::string& file, const std::string& path, const Image& image,
                  const std::map<std::string, std::string>& attributes = {});

// Reads what write_exr wrote (variance zero when absent). Throws InputError.
Image read_exr(const std::string& path);

// 8-bit sRGB PNG of rgb × 2^exposure, clamped. Written atomically.
void write_png(const std::string& path, const Image& image, float exposure = 0.0f);

// The same into `file`, opened and truncated (an OutputSet's temporary); messages name `path`.
void write_png_to(const std::string& file, const std::string& path, const Image& image,
                  float exposure = 0.0f);

}  // namespace mcrt
