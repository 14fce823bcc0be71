#include "render/environment_light.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "common/regular_file.h"

namespace mcrt {

namespace {

std::vector<unsigned char> read_bytes(const std::string& path) {
    std::vector<unsigned char> bytes;
    std::string why;
    if (!read_regular_file(path, bytes, why, FileSizeLimits{}))
        throw InputError(path + ": environment map " + why);
    return bytes;
}

// The readers take a file (OpenEXR's and stb_image's file readers): bytes from another rank go
// through a private temporary file of the same extension, removed once read.
EnvironmentMap load_from_bytes(const std::string& path, const std::vector<unsigned char>& bytes,
                               float scale) {
    static std::atomic<unsigned> next{0};
    const std::string ext = std::filesystem::path(path).extension().string();
    const std::filesystem::path temporary =
        std::filesystem::temp_directory_path() /
        ("mcrt-env-" + std::to_string(::getpid()) + "-" + std::to_string(next++) + ext);
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        if (!out) throw RuntimeError(temporary.string() + ": cannot write the environment map");
    }
    try {
        EnvironmentMap map = load_environment_map(temporary.string(), scale);
        std::filesystem::remove(temporary);
        return map;
    } catch (const InputError& e) {
        std::filesystem::remove(temporary);
        std::string what = e.what();
        if (size_t at = what.find(temporary.string()); at != std::string::npos)
            what.replace(at, temporary.string().size(), path);
        throw InputError(what);
    }
}

}  // namespace

std::shared_ptr<const EnvironmentLight> load_environment_light(const std::string& path, float scale,
                                                               float rotate_deg,
                                                               const FileBundle* bundle,
                                                               FileBundle* record) {
    auto env = std::make_shared<EnvironmentLight>();
    env->path = path;
    env->rotate_deg = rotate_deg;
    if (bundle) {
        auto it = bundle->find(path);
        if (it == bundle->end()) throw InputError(path + ": environment map not sent by rank 0");
        env->map = load_from_bytes(path, it->second, scale);
    } else {
        // A FIFO would block the readers, a directory or device read as garbage.
        if (const std::string why = why_not_regular_file(path); !why.empty())
            throw InputError(path + ": environment map " + why);
        env->map = load_environment_map(path, scale);
        if (record) (*record)[path] = read_bytes(path);
    }
    env->distribution = build_environment_distribution(env->map);
    env->power_unit_radius = environment_power(env->map, 1.0);
    return env;
}

uint32_t environment_pmf_steps(const EnvironmentLight& env, const GpuSceneData& scene,
                               LightSelection selection) {
    constexpr double kSteps = 16777216.0;  // the 2^-24 grid of the selection sample
    // Every light the selection chooses among: the area lights, then the punctual ones
    // (light_powers holds both), so that a scene lit by punctual lights alone still has them.
    const size_t n = scene.lights.size() + scene.punctual.size();
    double total = 0.0;
    for (double p : scene.light_powers) total += p;
    if (n == 0 || !(total > 0.0)) return uint32_t(kSteps);
    double share = 1.0 / double(n + 1);
    if (selection != LightSelection::Uniform) {
        // The radius of the scene's bounding sphere: half the diagonal of the root's boxes.
        const gpu::Bvh4Node& root = scene.nodes.front();
        const float* lo[3] = {&root.lo_x.x, &root.lo_y.x, &root.lo_z.x};
        const float* hi[3] = {&root.hi_x.x, &root.hi_y.x, &root.hi_z.x};
        double d2 = 0.0;
        for (int a = 0; a < 3; ++a) {
            double a_lo = INFINITY, a_hi = -INFINITY;
            for (int k = 0; k < 4; ++k) {
                if (lo[a][k] > hi[a][k]) continue;  // an empty slot's inverted box
                a_lo = std::min(a_lo, double(lo[a][k]));
                a_hi = std::max(a_hi, double(hi[a][k]));
            }
            if (a_hi >= a_lo) d2 += (a_hi - a_lo) * (a_hi - a_lo);
        }
        const double power = env.power_unit_radius * d2 / 4.0;
        share = power / (power + total);
    }
    const double steps = std::round(share * kSteps);
    return uint32_t(std::clamp(steps, 1.0, kSteps - 1.0));
}

std::vector<float> environment_words(const EnvironmentLight& env) {
    std::vector<float> words(env.map.rgb);
    words.insert(words.end(), env.distribution.cdf.begin(), env.distribution.cdf.end());
    return words;
}

}  // namespace mcrt
