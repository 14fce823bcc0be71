// Latitude-longitude environment maps (DESIGN.md "Environment map"): reading OpenEXR or Radiance
// .hdr files, Mitsuba 3's `envmap` mapping for a +Y-up scene, and the piecewise-constant
// distribution over texels that samples directions from it, with its pdf twin.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace mcrt {

// Largest map read: 2^23 texels (8192 × 1024 or 4096 × 2048), so that every texel with light
// gets at least one 2^-24 step of the sampling CDF (discrete.h); a header declaring more is
// refused before anything is allocated.
constexpr long long kMaxEnvironmentTexels = 1LL << 23;

// Radiance per texel, constant over the texel (nearest lookup); row 0 at the zenith.
struct EnvironmentMap {
    int width = 0, height = 0;
    std::vector<float> rgb;  // 3 per texel, row-major
};

// Reads `path` (.exr: float or half R, G, B; .hdr: Radiance RGBE) and multiplies it by `scale`.
// Throws InputError, naming the file, on an unreadable or truncated file, a size over
// kMaxEnvironmentTexels, a NaN, infinite or negative texel, or a map whose every texel is zero.
EnvironmentMap load_environment_map(const std::string& path, float scale);

// The map of one texel: `--sky R,G,B` as a map.
EnvironmentMap uniform_environment_map(const std::array<float, 3>& radiance);

// Map coordinates of world direction d (unit), the map turned `rotate_deg` about +Y
// (counter-clockwise seen from above): u = atan2(x, −z)/2π wrapped into [0, 1), v = acos(y)/π.
std::array<double, 2> environment_uv(const std::array<double, 3>& d, double rotate_deg);

// Texel (column, row) that holds direction d.
std::array<int, 2> environment_texel(const EnvironmentMap& map, const std::array<double, 3>& d,
                                     double rotate_deg);

// Solid angle of a texel of row j: (2π/W)(cos θ_j − cos θ_{j+1}), θ_j = πj/H.
double texel_solid_angle(int width, int height, int row);

// Rec. 709 luminance, the weight of a texel's radiance.
double environment_luminance(const float* rgb);

// Power for light selection: π r² ∫ Y(L(ω)) dω over the sphere, the light that crosses the disk of
// the scene's bounding sphere of radius r (PBRT 4th ed. §12.5.2, ImageInfiniteLight::Phi, with the
// texels' exact solid angles); a uniform sky of luminance Y gives 4π² r² Y.
double environment_power(const EnvironmentMap& map, double scene_radius);

// Sampling distribution: one CDF over all W·H texels ∝ luminance × texel solid angle, on the
// 2^-24 grid (build_cdf), so that cdf[k+1] − cdf[k] is exactly the probability of texel k.
struct EnvironmentDistribution {
    int width = 0, height = 0;
    std::vector<float> cdf;  // W·H + 1 entries; texel k = row·W + column
};

EnvironmentDistribution build_environment_distribution(const EnvironmentMap& map);

// A direction drawn from the distribution: u0 picks the texel by inversion, (u1, u2) a point
// uniform in φ and in cos θ within it, so uniform in solid angle over the texel (PBRT 4th ed.
// §12.5.2, with nearest texels). Returns the direction in the map's frame turned by rotate_deg.
std::array<double, 3> sample_environment(const EnvironmentDistribution& dist, double u0, double u1,
                                         double u2, double rotate_deg);

// Its pdf with respect to solid angle at direction d: p_texel / Ω_texel.
double environment_pdf_w(const EnvironmentDistribution& dist, const std::array<double, 3>& d,
                         double rotate_deg);

}  // namespace mcrt
