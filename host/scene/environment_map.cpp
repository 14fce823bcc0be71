// Environment maps: reading, mapping and sampling (environment_map.h).
#include "scene/environment_map.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common/error.h"
#include "common/value_limits.h"
#include "lights/discrete.h"

namespace mcrt {

namespace {

constexpr double kPi = 3.14159265358979323846;

bool ends_with(const std::string& s, const std::string& tail) {
    if (s.size() < tail.size()) return false;
    std::string end = s.substr(s.size() - tail.size());
    std::transform(end.begin(), end.end(), end.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    return end == tail;
}

void check_size(const std::string& path, long long width, long long height) {
    if (width < 1 || height < 1 || width * height > kMaxEnvironmentTexels) {
        throw InputError(path + ": environment map of " + std::to_string(width) + "x" +
                         std::to_string(height) + " texels; at most " +
                         std::to_string(kMaxEnvironmentTexels) + " texels are read");
    }
}

EnvironmentMap read_exr_map(const std::string& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i& window = file.header().dataWindow();
        const long long width = (long long)window.max.x - window.min.x + 1;
        const long long height = (long long)window.max.y - window.min.y + 1;
        check_size(path, width, height);
        for (const char* name : {"R", "G", "B"}) {
            if (!file.header().channels().findChannel(name)) {
                throw InputError(path + ": EXR environment map has no channel " + name);
            }
        }
        EnvironmentMap map;
        map.width = int(width);
        map.height = int(height);
        map.rgb.assign(3 * size_t(width) * size_t(height), 0.0f);
        // Channels of any pixel type (half or float) read into floats; the base pointer is
        // offset so that the data window's corner lands on texel 0 (OpenEXR "Reading and
        // Writing Image Files", Framebuffers).
        char* base =
            reinterpret_cast<char*>(map.rgb.data()) -
            (ptrdiff_t(window.min.x) + ptrdiff_t(window.min.y) * width) * 3 * sizeof(float);
        Imf::FrameBuffer frame;
        const char* names[3] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c) {
            frame.insert(names[c],
                         Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float),
                                    3 * sizeof(float) * size_t(width)));
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        return map;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read EXR environment map: " + e.what());
    }
}

// stb_image reads past a file's end as zeros; a read that finds no more bytes while it decodes
// means the file is truncated.
struct HdrSource {
    std::FILE* file = nullptr;
    bool ran_out = false;
};

int hdr_read(void* user, char* data, int size) {
    auto* source = static_cast<HdrSource*>(user);
    const size_t n = std::fread(data, 1, size_t(size), source->file);
    if (n == 0) source->ran_out = true;
    return int(n);
}
void hdr_skip(void* user, int n) { std::fseek(static_cast<HdrSource*>(user)->file, n, SEEK_CUR); }
int hdr_eof(void* user) { return std::feof(static_cast<HdrSource*>(user)->file); }

EnvironmentMap read_hdr_map(const std::string& path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                         std::fclose);
    if (!file) throw InputError(path + ": cannot open environment map");
    const stbi_io_callbacks callbacks{hdr_read, hdr_skip, hdr_eof};
    HdrSource source{file.get(), false};
    int width = 0, height = 0, channels = 0;
    // Each stb_image call reads from the file's start: is it .hdr, its declared size, then the
    // texels, once the size is within the limit.
    const bool is_hdr = stbi_is_hdr_from_callbacks(&callbacks, &source);
    std::rewind(file.get());
    if (!is_hdr || !stbi_info_from_callbacks(&callbacks, &source, &width, &height, &channels)) {
        throw InputError(path + ": not a Radiance .hdr image");
    }
    check_size(path, width, height);
    std::rewind(file.get());
    source.ran_out = false;
    std::unique_ptr<float, void (*)(void*)> pixels(
        stbi_loadf_from_callbacks(&callbacks, &source, &width, &height, &channels, 3),
        stbi_image_free);
    if (!pixels)
        throw InputError(path + ": cannot read .hdr environment map: " + stbi_failure_reason());
    if (source.ran_out) throw InputError(path + ": .hdr environment map is truncated");
    EnvironmentMap map;
    map.width = width;
    map.height = height;
    map.rgb.assign(pixels.get(), pixels.get() + 3 * size_t(width) * size_t(height));
    return map;
}

}  // namespace

EnvironmentMap load_environment_map(const std::string& path, float scale) {
    EnvironmentMap map;
    if (ends_with(path, ".exr")) {
        map = read_exr_map(path);
    } else if (ends_with(path, ".hdr")) {
        map = read_hdr_map(path);
    } else {
        throw InputError(path + ": environment map must be .exr or .hdr");
    }
    bool any_light = false;
    for (size_t k = 0; k < map.rgb.size(); ++k) {
        const float value = map.rgb[k];
        if (!std::isfinite(value) || value < 0.0f || double(value) * scale > kMaxRadiance) {
            const size_t texel = k / 3;
            throw InputError(path + ": environment map texel (" +
                             std::to_string(texel % map.width) + ", " +
                             std::to_string(texel / map.width) + ") is " + std::to_string(value) +
                             "; texels must be finite and non-negative");
        }
        map.rgb[k] = value * scale;
        any_light = any_light || map.rgb[k] > 0.0f;
    }
    if (!any_light) throw InputError(path + ": every texel of the environment map is zero");
    return map;
}

EnvironmentMap uniform_environment_map(const std::array<float, 3>& radiance) {
    return EnvironmentMap{1, 1, {radiance[0], radiance[1], radiance[2]}};
}

std::array<double, 2> environment_uv(const std::array<double, 3>& d, double rotate_deg) {
    // The map turned by a about +Y shows at world d what it holds at R_y(−a) d.
    const double a = rotate_deg * kPi / 180.0;
    const double x = d[0] * std::cos(a) - d[2] * std::sin(a);
    const double z = d[0] * std::sin(a) + d[2] * std::cos(a);
    double u = std::atan2(x, -z) / (2.0 * kPi);
    if (u < 0.0) u += 1.0;
    if (u >= 1.0) u = 0.0;
    const double v = std::acos(std::clamp(d[1], -1.0, 1.0)) / kPi;
    return {u, v};
}

std::array<int, 2> environment_texel(const EnvironmentMap& map, const std::array<double, 3>& d,
                                     double rotate_deg) {
    const auto uv = environment_uv(d, rotate_deg);
    return {std::min(int(uv[0] * map.width), map.width - 1),
            std::min(int(uv[1] * map.height), map.height - 1)};
}

double texel_solid_angle(int width, int height, int row) {
    return (2.0 * kPi / width) *
           (std::cos(kPi * row / height) - std::cos(kPi * (row + 1) / height));
}

double environment_luminance(const float* rgb) {
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

double environment_power(const EnvironmentMap& map, double scene_radius) {
    double integral = 0;
    for (int j = 0; j < map.height; ++j) {
        double row = 0;
        for (int i = 0; i < map.width; ++i) {
            row += environment_luminance(&map.rgb[3 * (size_t(j) * map.width + i)]);
        }
        integral += row * texel_solid_angle(map.width, map.height, j);
    }
    return kPi * scene_radius * scene_radius * integral;
}

EnvironmentDistribution build_environment_distribution(const EnvironmentMap& map) {
    std::vector<double> weights(size_t(map.width) * map.height);
    for (int j = 0; j < map.height; ++j) {
        const double omega = texel_solid_angle(map.width, map.height, j);
        for (int i = 0; i < map.width; ++i) {
            const size_t k = size_t(j) * map.width + i;
            weights[k] = environment_luminance(&map.rgb[3 * k]) * omega;
        }
    }
    return EnvironmentDistribution{map.width, map.height, build_cdf(weights)};
}

std::array<double, 3> sample_environment(const EnvironmentDistribution& dist, double u0, double u1,
                                         double u2, double rotate_deg) {
    // Largest k with cdf[k] <= u0 among non-empty intervals (kernels/sampling/discrete.cl's
    // inversion).
    const auto it = std::upper_bound(dist.cdf.begin(), dist.cdf.end(), float(u0));
    size_t k = size_t(std::max<ptrdiff_t>(it - dist.cdf.begin() - 1, 0));
    k = std::min(k, dist.cdf.size() - 2);
    const int i = int(k % dist.width), j = int(k / dist.width);
    const double phi = 2.0 * kPi * (i + u1) / dist.width;
    const double cos_top = std::cos(kPi * j / dist.height);
    const double cos_bottom = std::cos(kPi * (j + 1) / dist.height);
    const double cos_theta = cos_top + u2 * (cos_bottom - cos_top);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    // Map frame: x = sinθ sinφ, z = −sinθ cosφ (u = atan2(x, −z)/2π); then turned by R_y(a).
    const double xm = sin_theta * std::sin(phi), zm = -sin_theta * std::cos(phi);
    const double a = rotate_deg * kPi / 180.0;
    return {xm * std::cos(a) + zm * std::sin(a), cos_theta, -xm * std::sin(a) + zm * std::cos(a)};
}

double environment_pdf_w(const EnvironmentDistribution& dist, const std::array<double, 3>& d,
                         double rotate_deg) {
    const auto uv = environment_uv(d, rotate_deg);
    const int i = std::min(int(uv[0] * dist.width), dist.width - 1);
    const int j = std::min(int(uv[1] * dist.height), dist.height - 1);
    const size_t k = size_t(j) * dist.width + i;
    const double pmf = double(dist.cdf[k + 1]) - double(dist.cdf[k]);
    return pmf / texel_solid_angle(dist.width, dist.height, j);
}

}  // namespace mcrt
