// Glass: KHR_materials_ior, _transmission and _volume (kernels/materials/bsdf.cl, -D
// MCRT_TRANSMISSION): what the importer reads and refuses, the F0 the index of refraction gives
// every dielectric, and scenes without these extensions unchanged.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "chi2.h"
#include "common/error.h"
#include "image_bytes.h"
#include "independent_renders.h"
#include "kernel_program.h"
#include "render/gpu_scene.h"
#include "render/plan.h"
#include "render/renderer.h"
#include "scene/gltf_import.h"
#include "scene_builders.h"

using namespace mcrt;
using namespace mcrt::test;
using glm::dvec3;

namespace {

// ---- One triangle with a material written in JSON ----------------------------------------------

std::string triangle_gltf(const std::string& material) {
    const float p[9] = {-1, 0, 1, 1, 0, 1, 0, 0, -1};
    const uint16_t indices[3] = {0, 1, 2};
    Bytes bytes(sizeof p + sizeof indices);
    std::memcpy(bytes.data(), p, sizeof p);
    std::memcpy(bytes.data() + sizeof p, indices, sizeof indices);
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}], "materials": [)" +
           material + R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0},
        "indices": 1, "material": 0}]}],
        "buffers": [{"byteLength": 42, "uri": "data:application/octet-stream;base64,)" +
           base64(bytes) + R"("}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [-1, 0, -1], "max": [1, 0, 1]},
                      {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
}

struct Loaded {
    Material material;
    std::vector<std::string> warnings;
};

// The material of `extensions` (the JSON object's members) on a dielectric (metallic 0).
Loaded load_material(const std::string& extensions) {
    const std::string text = triangle_gltf(
        R"({"pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": {)" + extensions + "}}");
    Loaded l;
    Scene s =
        load_gltf_from_memory("glass.gltf", std::vector<unsigned char>(text.begin(), text.end()),
                              [&](const std::string& w) { l.warnings.push_back(w); });
    l.material = s.materials.at(0);
    return l;
}

std::string refusal(const std::string& extensions) {
    try {
        load_material(extensions);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

// The dielectric's F0 as the host packs it for the kernels (host/render/gpu_scene.cpp).
glm::vec4 packed_specular(const Material& m) {
    Scene s;
    s.materials.push_back(m);
    add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    const gpu::float4 v = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1).materials[0].specular;
    return glm::vec4(v.x, v.y, v.z, v.w);
}

}  // namespace

// ---- KHR_materials_ior ------------------------------------------------------------------------

TEST_CASE("KHR_materials_ior sets every dielectric's F0; ior 1.5 gives exactly 0.04",
          "[glass][ior]") {
    SECTION("absent: 1.5, and the F0 the kernels had before the extension, to the bit") {
        const Loaded l = load_material("");
        CHECK(l.warnings.empty());
        CHECK(l.material.ior == 1.5f);
        const glm::vec4 f = packed_specular(l.material);
        CHECK(f.x == 0.04f);
        CHECK(f.w == 1.0f);
    }
    SECTION("F0 = ((ior - 1)/(ior + 1))^2, times KHR_materials_specular's colour and factor") {
        const Loaded l = load_material(R"("KHR_materials_ior": {"ior": 1.33},
            "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 2, 0.5]})");
        CHECK(l.warnings.empty());
        REQUIRE(l.material.ior == 1.33f);
        const double f0 = std::pow((1.33 - 1.0) / (1.33 + 1.0), 2.0);
        const glm::vec4 f = packed_specular(l.material);
        CHECK(f.x == Approx(f0 * 0.5).epsilon(1e-6));
        CHECK(f.y == Approx(2.0 * f0 * 0.5).epsilon(1e-6));
        CHECK(f.z == Approx(0.5 * f0 * 0.5).epsilon(1e-6));
        CHECK(f.w == 0.5f);
    }
    SECTION("ior 0 is the extension's specular-glossiness mode: F0 = 1") {
        const Loaded l = load_material(R"("KHR_materials_ior": {"ior": 0})");
        CHECK(l.warnings.empty());
        CHECK(l.material.ior == 0.0f);
        CHECK(packed_specular(l.material).x == 1.0f);
    }
    SECTION("below 1 (not 0): the default with one warning; huge: clamped with one warning") {
        for (const char* bad : {"-2", "0.5", "1e-30"}) {
            INFO(bad);
            const Loaded l =
                load_material(std::string(R"("KHR_materials_ior": {"ior": )") + bad + "}");
            REQUIRE(l.warnings.size() == 1);
            CHECK(l.warnings[0].find("KHR_materials_ior.ior") != std::string::npos);
            CHECK(l.material.ior == 1.5f);
        }
        const Loaded huge = load_material(R"("KHR_materials_ior": {"ior": 1e300})");
        REQUIRE(huge.warnings.size() == 1);
        CHECK(huge.warnings[0].find("clamped") != std::string::npos);
        CHECK(huge.material.ior == 1e4f);
        const glm::vec4 f = packed_specular(huge.material);
        CHECK(std::isfinite(f.x));
        CHECK(f.x > 0.999f);
    }
    SECTION("not a finite number: refused, naming the material and the property") {
        CHECK(refusal(R"("KHR_materials_ior": {"ior": 1e999})") != "(loaded)");
        for (const char* bad : {"\"glass\"", "[1.5]", "true"}) {
            INFO(bad);
            const std::string e =
                refusal(std::string(R"("KHR_materials_ior": {"ior": )") + bad + "}");
            CHECK(e.find("material 0") != std::string::npos);
            CHECK(e.find("KHR_materials_ior.ior must be a finite number") != std::string::npos);
        }
    }
}

// ---- KHR_materials_transmission and KHR_materials_volume ---------------------------------------

TEST_CASE("transmission and volume are read; bad values warn once with a fallback or are refused",
          "[glass][gltf]") {
    SECTION("transmission alone: thin-walled, not Lambertian, built with -D MCRT_TRANSMISSION") {
        const Loaded l =
            load_material(R"("KHR_materials_transmission": {"transmissionFactor": 0.75})");
        CHECK(l.warnings.empty());
        CHECK(l.material.transmission == 0.75f);
        CHECK_FALSE(l.material.volume);
        CHECK_FALSE(l.material.lambertian());
        Scene s;
        s.materials.push_back(l.material);
        add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
        RenderSettings settings;
        GpuSceneData data = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1);
        CHECK(data.transmission);
        CHECK(data.materials[0].transmission == 0.75f);
        CHECK((data.materials[0].flags & MATERIAL_VOLUME) == 0u);
        CHECK(make_render_plan(settings, data).program_options.find("-D MCRT_TRANSMISSION") !=
              std::string::npos);
        // --materials lambert reads the same surface as opaque Lambertian: no glass code.
        make_lambertian(s.materials);
        GpuSceneData flat = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1);
        CHECK_FALSE(flat.transmission);
        CHECK(make_render_plan(settings, flat).program_options.find("MCRT_TRANSMISSION") ==
              std::string::npos);
    }
    SECTION("a scene without transmission builds without the glass code") {
        const Loaded l = load_material(R"("KHR_materials_ior": {"ior": 1.7})");
        Scene s;
        s.materials.push_back(l.material);
        add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
        GpuSceneData data = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1);
        CHECK(data.microfacet);
        CHECK_FALSE(data.transmission);
        CHECK(make_render_plan(RenderSettings{}, data).program_options.find("MCRT_TRANSMISSION") ==
              std::string::npos);
    }
    SECTION("a volume: attenuation in bits per unit length, -log2(colour)/distance") {
        const Loaded l = load_material(R"("KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationDistance": 2,
                                     "attenuationColor": [0.5, 1, 0.25]})");
        // One triangle bounds no volume: one warning, the render goes on.
        REQUIRE(l.warnings.size() == 1);
        CHECK(l.warnings[0].find("not closed (3 of its 3 edges") != std::string::npos);
        REQUIRE(l.material.volume);
        const glm::dvec3 a = volume_attenuation(l.material);
        CHECK(a.x == Approx(0.5));
        CHECK(a.y == 0.0);
        CHECK(a.z == Approx(1.0));
        Scene s;
        s.materials.push_back(l.material);
        add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
        const gpu::Material g = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1).materials[0];
        CHECK((g.flags & MATERIAL_VOLUME) != 0u);
        CHECK(g.attenuation.x == Approx(0.5f));
    }
    SECTION("a volume without transmission, or of thickness 0, is no volume") {
        CHECK_FALSE(
            load_material(R"("KHR_materials_volume": {"thicknessFactor": 1})").material.volume);
        CHECK_FALSE(load_material(R"("KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 0})")
                        .material.volume);
    }
    SECTION("attenuationDistance <= 0: no attenuation, one warning; colour clamped; black finite") {
        for (const char* d : {"0", "-3"}) {
            const Loaded l = load_material(
                std::string(R"("KHR_materials_transmission": {"transmissionFactor": 1},
                "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": )") +
                d + "}");
            REQUIRE(l.warnings.size() == 2);  // and the open surface's
            CHECK(l.warnings[0].find("attenuationDistance") != std::string::npos);
            CHECK(volume_attenuation(l.material) == glm::dvec3(0.0));
        }
        const Loaded c = load_material(R"("KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": 1,
                                     "attenuationColor": [2, 0, 0.5]})");
        REQUIRE(c.warnings.size() == 2);  // and the open surface's
        CHECK(c.warnings[0].find("clamped") != std::string::npos);
        const glm::dvec3 a = volume_attenuation(c.material);
        CHECK(a.x == 0.0);
        CHECK(a.y == 1e30);  // black: everything absorbed, yet 0 * a stays 0
        CHECK(a.z == Approx(1.0));
    }
    SECTION("a closed volume loads without a warning") {
        std::vector<std::string> warnings;
        const Scene s = load_gltf(std::string(MCRT_SCENES) + "/glass/glass-sphere.gltf",
                                  [&](const std::string& w) { warnings.push_back(w); });
        CHECK(warnings.empty());
        bool volume = false;
        for (const Material& m : s.materials) volume = volume || m.volume;
        CHECK(volume);
    }
    SECTION("transmissionTexture: its index is checked, a texture without image is warned about") {
        // The triangle's file has no textures: index 0 names nothing.
        CHECK(
            refusal(
                R"("KHR_materials_transmission": {"transmissionFactor": 1, "transmissionTexture": {"index": 0}})")
                .find("texture") != std::string::npos);
        CHECK(
            refusal(
                R"("KHR_materials_transmission": {"transmissionFactor": 1, "transmissionTexture": {"index": 4294967296}})")
                .find("transmissionTexture.index") != std::string::npos);
        CHECK(
            refusal(
                R"("KHR_materials_transmission": {"transmissionFactor": 1, "transmissionTexture": {"texCoord": 0}})")
                .find("transmissionTexture.index: required") != std::string::npos);
        CHECK(
            refusal(
                R"("KHR_materials_transmission": {"transmissionFactor": 1, "transmissionTexture": 3})")
                .find("transmissionTexture") != std::string::npos);
    }
    SECTION("refused: non-numbers, a negative thickness, a malformed colour") {
        CHECK(refusal(R"("KHR_materials_transmission": {"transmissionFactor": "all"})")
                  .find("transmissionFactor must be a finite number") != std::string::npos);
        CHECK(refusal(R"("KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": -1})")
                  .find("thicknessFactor must be a finite number >= 0") != std::string::npos);
        CHECK(refusal(R"("KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 1, "attenuationColor": [1, 1]})")
                  .find("attenuationColor must be 3 numbers") != std::string::npos);
        CHECK(refusal(R"("KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": "far"})")
                  .find("attenuationDistance must be a number > 0") != std::string::npos);
    }
}

// ---- The BSDF's kernels: sampling against its pdf twin, delta lobes, Fresnel -------------------

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr size_t kSamples = 1000000;
// The χ² tests of this file share a family-wise significance of 1% (Bonferroni).
constexpr int kChi2Tests = 8;
constexpr double kAlpha = 0.01 / kChi2Tests;

struct Glass {
    dvec3 base{1.0};
    double metallic = 0.0, roughness = 0.0, transmission = 1.0, ior = 1.5;
    bool volume = false;
    bool front = true;  // seen from the front face (outside a volume)
    std::string label;

    Material scene_material() const {
        Material m;
        m.albedo = glm::vec3(base);
        m.metallic = float(metallic);
        m.roughness = float(roughness);
        m.specular = 1.0f;
        m.transmission = float(transmission);
        m.ior = float(ior);
        m.volume = volume;
        return m;
    }
    gpu::Material packed() const {
        Scene s;
        s.materials.push_back(scene_material());
        add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
        return make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1).materials[0];
    }
};

KernelProgram& glass_device() {
    static KernelProgram d("bsdf_test.cl",
                           "-D MCRT_MATERIALS_GLTF -D MCRT_TRANSMISSION "
                           "-D LIGHT_SELECT_POWER -D SAMPLER_INDEPENDENT");
    return d;
}

cl_float4 f4(const dvec3& v, float w = 0.0f) { return {{float(v.x), float(v.y), float(v.z), w}}; }
dvec3 d3(const cl_float4& v) { return dvec3(v.s[0], v.s[1], v.s[2]); }

dvec3 view_at(double theta_degrees) {
    double t = theta_degrees * kPi / 180.0;
    return dvec3(std::sin(t), 0.0, std::cos(t));
}

struct GlassSamples {
    std::vector<cl_float4> wi_pdf, f_cos;
    std::vector<cl_uint> lobe;
    // f·|cosθ|/pdf of sample k (its first channel); 0 for no sample.
    double weight(size_t k) const {
        return wi_pdf[k].s[3] > 0 ? f_cos[k].s[0] * f_cos[k].s[3] / wi_pdf[k].s[3] : 0.0;
    }
};

GlassSamples sample_glass(const Glass& g, dvec3 wo, size_t n, cl_uint seed) {
    KernelProgram& d = glass_device();
    cl::Buffer out = d.output<cl_float4>(n), f = d.output<cl_float4>(n),
               lobe = d.output<cl_uint>(n);
    d.run("glass_samples", n, g.packed(), f4(wo), cl_uint(g.front), cl_uint(n), seed, out, f, lobe);
    return {d.read<cl_float4>(out, n), d.read<cl_float4>(f, n), d.read<cl_uint>(lobe, n)};
}

void evaluate_glass(const Glass& g, dvec3 wo, const std::vector<cl_float4>& wi,
                    std::vector<float>* pdf, std::vector<cl_float4>* f) {
    KernelProgram& d = glass_device();
    cl::Buffer in = d.buffer(wi), p = d.output<float>(wi.size()),
               fb = d.output<cl_float4>(wi.size());
    d.run("glass_evaluate", wi.size(), g.packed(), f4(wo), cl_uint(g.front), cl_uint(wi.size()), in,
          p, fb);
    if (pdf) *pdf = d.read<float>(p, wi.size());
    if (f) *f = d.read<cl_float4>(fb, wi.size());
}

// A (θ, φ) grid over the whole sphere of directions, dω = sinθ dθ dφ; the last cell holds the
// samples that are no direction (pdf 0).
struct SphereGrid {
    int nt = 64, np = 64;
    int cells() const { return nt * np + 1; }
    double dt() const { return kPi / nt; }
    double dp() const { return 2.0 * kPi / np; }
    int cell_of(dvec3 w, float pdf) const {
        if (!(pdf > 0.0f)) return nt * np;
        double t = std::acos(std::clamp(w.z, -1.0, 1.0)), p = std::atan2(w.y, w.x) + kPi;
        int it = std::min(nt - 1, int(t / dt())), ip = std::min(np - 1, int(p / dp()));
        return it * np + ip;
    }
    dvec3 direction(double t, double p) const {
        p -= kPi;
        return dvec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
    }
};

// The expected fraction of samples in each cell (chi2.h, expected_cell_fractions).
std::vector<double> expected_fractions(const Glass& glass, dvec3 wo, const SphereGrid& g, int m,
                                       int fine) {
    return expected_cell_fractions(g, m, fine, [&](const std::vector<dvec3>& directions) {
        std::vector<cl_float4> w;
        for (const dvec3& d : directions) w.push_back(f4(d));
        std::vector<float> pdf;
        evaluate_glass(glass, wo, w, &pdf, nullptr);
        return pdf;
    });
}

// χ² of a rough glass's samples against its pdf twin over the sphere, and each sample's f and
// pdf against bsdf_eval and bsdf_pdf_w at its direction.
void glass_chi2(const Glass& glass, double view_degrees, cl_uint seed) {
    const dvec3 wo = view_at(view_degrees);
    SphereGrid g;
    GlassSamples s = sample_glass(glass, wo, kSamples, seed);
    std::vector<double> observed(g.cells(), 0.0);
    size_t bad = 0, deltas = 0, transmitted = 0;
    for (size_t k = 0; k < kSamples; ++k) {
        const cl_float4& x = s.wi_pdf[k];
        dvec3 w = d3(x);
        if (!std::isfinite(x.s[3]) || (x.s[3] > 0 && std::abs(glm::length(w) - 1.0) > 1e-5)) ++bad;
        deltas += (s.lobe[k] & 1u) ? 1 : 0;
        transmitted += x.s[3] > 0 && w.z < 0 ? 1 : 0;
        observed[g.cell_of(w, x.s[3])] += 1;
    }
    std::vector<double> expected = expected_fractions(glass, wo, g, 6, 32);
    for (double& e : expected) e *= double(kSamples);
    char name[160];
    std::snprintf(name, sizeof name, "glass %s rough %.2f view %.0f deg", glass.label.c_str(),
                  glass.roughness, view_degrees);
    Chi2 r = chi2_test(name, observed, expected, kAlpha);
    INFO(name);
    CHECK(bad == 0);
    CHECK(deltas == 0);
    CHECK(transmitted > 2000);  // the transmitted lobe is tested, not left empty
    CHECK(r.statistic < r.critical);

    // The sample's f and pdf are bsdf_eval's and bsdf_pdf_w's at its direction.
    std::vector<cl_float4> wi(s.wi_pdf.begin(), s.wi_pdf.begin() + 20000);
    std::vector<float> pdf;
    std::vector<cl_float4> f;
    evaluate_glass(glass, wo, wi, &pdf, &f);
    size_t mismatched = 0;
    for (size_t k = 0; k < wi.size(); ++k) {
        if (!(wi[k].s[3] > 0)) continue;
        bool same = std::abs(pdf[k] - wi[k].s[3]) <= 1e-4 * wi[k].s[3];
        for (int c = 0; c < 3; ++c)
            same =
                same && std::abs(f[k].s[c] - s.f_cos[k].s[c]) <= 1e-4 * std::abs(s.f_cos[k].s[c]);
        mismatched += same ? 0 : 1;
    }
    CHECK(mismatched == 0);
}

Glass rough(double roughness, bool volume, bool front, const char* label) {
    Glass g;
    g.roughness = roughness;
    g.volume = volume;
    g.front = front;
    g.label = label;
    return g;
}

// The exact unpolarised Fresnel reflectance in double (PBRT 4th ed. eq. 9.5).
double fresnel_reference(double c, double eta) {
    double s2 = (1.0 - c * c) / (eta * eta);
    if (s2 >= 1.0) return 1.0;
    double ct = std::sqrt(1.0 - s2);
    double rp = (eta * c - ct) / (eta * c + ct), rs = (c - eta * ct) / (c + eta * ct);
    return 0.5 * (rp * rp + rs * rs);
}

}  // namespace

TEST_CASE("rough glass: sampling matches its pdf twin (chi2) on both lobes, thin and volume",
          "[glass][chi2]") {
    glass_chi2(rough(0.4, false, true, "thin"), 30.0, 1);
    glass_chi2(rough(0.4, false, true, "thin"), 75.0, 2);
    glass_chi2(rough(0.4, true, true, "volume entering"), 30.0, 3);
    glass_chi2(rough(0.4, true, true, "volume entering"), 75.0, 4);
    glass_chi2(rough(0.4, true, false, "volume leaving"), 20.0, 5);
    glass_chi2(rough(0.7, true, false, "volume leaving"), 60.0, 6);
    Glass mixed = rough(0.5, true, true, "mixed");
    mixed.base = dvec3(0.9, 0.6, 0.3);
    mixed.metallic = 0.2;
    mixed.transmission = 0.5;
    glass_chi2(mixed, 45.0, 7);
    Glass dense = rough(0.3, true, true, "ior 2.4");
    dense.ior = 2.4;
    glass_chi2(dense, 60.0, 8);
}

TEST_CASE("smooth glass is a pair of delta lobes chosen by the exact Fresnel term",
          "[glass][delta]") {
    const size_t n = 200000;
    for (bool volume : {false, true})
        for (bool front : {true, false})
            for (double view : {0.0, 30.0, 60.0, 85.0}) {
                if (!volume && !front) continue;
                Glass g = rough(0.0, volume, front, "smooth");
                const dvec3 wo = view_at(view);
                const double eta = !volume || front ? 1.5 : 1.0 / 1.5;
                const double R = fresnel_reference(wo.z, eta);
                GlassSamples s = sample_glass(g, wo, n, 21);
                size_t reflected = 0, wrong = 0;
                for (size_t k = 0; k < n; ++k) {
                    const dvec3 w = d3(s.wi_pdf[k]);
                    const bool reflect = w.z > 0;
                    reflected += reflect ? 1 : 0;
                    // The direction: the mirror, straight through, or Snell's refraction.
                    dvec3 expected = reflect ? dvec3(-wo.x, -wo.y, wo.z) : -wo;
                    if (!reflect && volume) {
                        double st = std::sin(std::acos(wo.z)) / eta;
                        expected = dvec3(-st, 0.0, -std::sqrt(1.0 - st * st));
                    }
                    // The weight f·cosθ/pdf: 1 reflected, 1/η² refracted into a volume.
                    const double weight = reflect || !volume ? 1.0 : 1.0 / (eta * eta);
                    wrong += (s.lobe[k] & 1u) && glm::length(w - expected) < 1e-5 &&
                                     std::abs(s.weight(k) - weight) < 1e-5 * weight
                                 ? 0
                                 : 1;
                }
                const double p = double(reflected) / n, se = std::sqrt(R * (1 - R) / n);
                INFO((volume ? "volume" : "thin") << (front ? " front" : " back") << " view "
                                                  << view << ": reflected " << p << ", R " << R);
                CHECK(wrong == 0);
                CHECK(std::abs(p - R) <= 4.5 * se + 1e-12);
                // Delta lobes have no density: the light strategies see no glass.
                std::vector<float> pdf;
                std::vector<cl_float4> f;
                evaluate_glass(g, wo, {f4(dvec3(-wo.x, -wo.y, wo.z)), f4(-wo)}, &pdf, &f);
                CHECK(pdf[0] == 0.0f);
                CHECK(pdf[1] == 0.0f);
                CHECK(d3(f[0]) == dvec3(0.0));
                CHECK(d3(f[1]) == dvec3(0.0));
            }
}

namespace {

// ∫ D(h) V(wo, wi) cosθ_i dω_i over the reflected directions of GGX α with the height-correlated
// V (glTF Appendix B), in double: the albedo of a white mirror-like lobe with F = 1, which is
// also a thin-walled glass's, reflected plus transmitted (F + (1 − F) = 1), whatever its ior.
// Integrated over half vectors, dω_i = 4 |wo·h| dω_h, θ_h = (π/2)s² dense at the pole.
double ggx_single_scattering_albedo(double alpha, dvec3 wo) {
    const int ns = 2048, np = 256;
    const double a2 = alpha * alpha;
    auto lambda_root = [&](double c) { return std::sqrt(a2 + (1.0 - a2) * c * c); };
    double sum = 0;
    for (int i = 0; i < ns; ++i)
        for (int j = 0; j < np; ++j) {
            const double sv = (i + 0.5) / ns, t = 0.5 * kPi * sv * sv;
            const double p = 2.0 * kPi * (j + 0.5) / np;
            const dvec3 h(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
            const double oh = glm::dot(wo, h);
            if (oh <= 0) continue;
            const dvec3 wi = 2.0 * oh * h - wo;
            if (wi.z <= 0) continue;
            const double D = a2 / (kPi * std::pow(h.z * h.z * (a2 - 1.0) + 1.0, 2.0));
            const double V = 0.5 / (wi.z * lambda_root(wo.z) + wo.z * lambda_root(wi.z));
            sum += D * V * wi.z * 4.0 * oh * std::sin(t) * (kPi * sv / ns) * (2.0 * kPi / np);
        }
    return sum;
}

}  // namespace

TEST_CASE("rough glass loses energy only to single scattering, and never more than arrives",
          "[glass][energy]") {
    const size_t n = 400000;
    for (bool volume : {false, true})
        for (double roughness : {0.2, 0.5, 1.0})
            for (double view : {0.0, 45.0, 80.0}) {
                Glass g = rough(roughness, volume, true, "energy");
                GlassSamples s = sample_glass(g, view_at(view), n, 31);
                // Radiance entering a volume is scaled by 1/η²: count the transmitted lobe's
                // energy as η² times its weight.
                double sum = 0, sum2 = 0;
                for (size_t k = 0; k < n; ++k) {
                    double v = s.weight(k) * (volume && d3(s.wi_pdf[k]).z < 0 ? 2.25 : 1.0);
                    REQUIRE(std::isfinite(v));
                    sum += v;
                    sum2 += v * v;
                }
                const double mean = sum / n,
                             se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
                INFO((volume ? "volume" : "thin") << " roughness " << roughness << " view " << view
                                                  << ": albedo " << mean << " +- " << se);
                CHECK(mean <= 1.0 + 4.5 * se);
                if (!volume) {
                    // Thin-walled: exactly the GGX lobe's single-scattering albedo.
                    const double alpha = std::max(roughness * roughness, 1e-3);
                    const double expected = ggx_single_scattering_albedo(alpha, view_at(view));
                    INFO("single-scattering albedo " << expected);
                    CHECK(std::abs(mean - expected) <= 4.5 * se + 1e-4);
                } else {
                    CHECK(mean > (roughness < 0.5 ? 0.9 : 0.4));
                }
            }
}

TEST_CASE("the exact Fresnel term and exp2 agree with double precision", "[glass][fresnel]") {
    KernelProgram& d = glass_device();
    std::vector<cl_float2> in;
    for (int k = 0; k <= 4096; ++k) in.push_back({{float(-149.0 * k / 4096.0), float(k / 4096.0)}});
    for (double eta : {1.5, 1.0 / 1.5, 1.33, 2.4, 1.0}) {
        cl::Buffer b = d.buffer(in), out = d.output<cl_float2>(in.size());
        d.run("dielectric_values", in.size(), cl_uint(in.size()), float(eta), b, out);
        std::vector<cl_float2> v = d.read<cl_float2>(out, in.size());
        double worst_exp = 0, worst_fresnel = 0;
        for (size_t k = 0; k < in.size(); ++k) {
            const double x = in[k].s[0], e = std::exp2(x);
            if (e > 1e-37) worst_exp = std::max(worst_exp, std::abs(v[k].s[0] - e) / e);
            worst_fresnel = std::max(
                worst_fresnel, std::abs(v[k].s[1] - fresnel_reference(in[k].s[1], float(eta))));
        }
        INFO("eta " << eta << ": exp2 relative error " << worst_exp << ", Fresnel "
                    << worst_fresnel);
        CHECK(worst_exp < 2.5e-7);  // 2 ulp
        CHECK(worst_fresnel < 1e-5);
    }
}

// ---- The white furnace: a glass sphere under a uniform sky
// ---------------------------------------

namespace {

// A smooth glass sphere (radius 1 at the origin, 48 × 24 facets) filling most of a 12 × 12 view,
// under the sky light of radiance 1: light is only redirected, never lost, so every pixel is 1.
struct GlassFurnace {
    Scene scene;
    Camera camera = looking_down(glm::vec3(0.0f, 3.0f, 0.0f), glm::radians(45.0f));

    explicit GlassFurnace(const Glass& glass) {
        scene.materials.push_back(glass.scene_material());
        add_sphere(scene, glm::vec3(0.0f), 1.0f, 48, 24, 0);
    }
};

struct FurnaceCheck {
    double worst_z = 0, mean = 0, mean_se = 0;
    size_t glass_pixels = 0, exact_pixels = 0, wrong_exact = 0;
    uint64_t nan_samples = 0;
};

// Per pixel and channel, z = (value − 1)/√variance (the variance of the pixel mean, from the
// EXR's layer); pixels that see only the sky have variance 0 and must be exactly 1.
FurnaceCheck furnace_check(const RenderResult& r) {
    FurnaceCheck c;
    double sum = 0, var = 0;
    const size_t n = r.image.rgb.size();
    for (size_t i = 0; i < n; ++i) {
        const double v = r.image.rgb[i], s2 = r.image.variance[i];
        sum += v;
        var += s2;
        if (s2 > 0) {
            // 1e-6: the float rounding of an average of 1s (ior 1 passes light unchanged).
            c.worst_z =
                std::max(c.worst_z, std::max(0.0, std::abs(v - 1.0) - 1e-6) / std::sqrt(s2));
            ++c.glass_pixels;
        } else {
            ++c.exact_pixels;
            c.wrong_exact += v == 1.0 ? 0 : 1;
        }
    }
    c.mean = sum / double(n);
    c.mean_se = std::sqrt(var) / double(n);
    c.nan_samples = r.nan_samples;
    return c;
}

RenderSettings furnace_settings(const std::string& estimator) {
    RenderSettings settings;
    settings.width = 12;
    settings.height = 12;
    // Roulette makes a sample 0 or 1/0.95^k: at a few hundred samples a pixel's mean is too
    // skewed for a normal z (|z| up to 4.9 at 256 spp where no roulette gives 1 exactly).
    settings.spp = 4096;
    settings.sky = glm::vec3(1.0f);
    settings.sky_light = true;
    // Not 64: a ray that enters near the silhouette meets the inside at nearly the critical
    // angle, where the Fresnel term is nearly 1, and circles inside for hundreds of reflections;
    // at depth 64 the rim pixels lose 1-2% (the image mean 0.9972 +- 0.0001 at 1024 spp without
    // roulette, 1 +- 1e-10 at depth 1000).
    settings.max_depth = MCRT_MAX_PATH_DEPTH;
    settings.rr_depth = 3;
    settings.estimator = estimator;
    settings.seed = 5;
    return settings;
}

}  // namespace

TEST_CASE("white furnace: a smooth glass sphere under a sky of radiance 1 renders 1 everywhere",
          "[glass][furnace]") {
    DeviceContext device = first_device();
    for (bool volume : {false, true})
        for (uint32_t rr_depth : {3u, MCRT_MAX_PATH_DEPTH})
            for (const char* estimator : {"mis", "bsdf", "light-area"}) {
                Glass glass = rough(0.0, volume, true, "furnace");
                GlassFurnace f(glass);
                RenderSettings settings = furnace_settings(estimator);
                settings.rr_depth = rr_depth;
                GpuSceneData data = gpu_scene_for(f.scene, f.camera, settings);
                REQUIRE(data.transmission);
                REQUIRE(
                    make_render_plan(settings, data).program_options.find("-D MCRT_TRANSMISSION") !=
                    std::string::npos);
                const FurnaceCheck c = furnace_check(render(device, data, settings));
                INFO((volume ? "volume" : "thin-walled")
                     << ", " << estimator << ", roulette from " << rr_depth << ": mean " << c.mean
                     << " +- " << c.mean_se << ", worst |z| " << c.worst_z << " over "
                     << c.glass_pixels << " pixel channels");
                CHECK(c.nan_samples == 0);
                CHECK(c.glass_pixels > 300);  // most of the 432 pixel channels see the glass
                CHECK(c.wrong_exact == 0);
                // 144 pixels (their channels alike): |z| < 4.5 for each holds with 99.9% for normal
                // means.
                CHECK(c.worst_z < 4.5);
                CHECK(std::abs(c.mean - 1.0) < 4.5 * c.mean_se + 1e-6);
                // Not vacuous. Inside a volume, roulette meets paths of hundreds of reflections:
                // their survivors' weights 1/0.95^k make its spread large. Without roulette every
                // sample is 1 to rounding.
                CHECK(c.mean_se < (rr_depth == MCRT_MAX_PATH_DEPTH ? 1e-6 : volume ? 1e-2 : 1e-4));
            }
}

TEST_CASE("the furnace sees a tinted or absorbing glass sphere: the check can fail",
          "[glass][furnace]") {
    DeviceContext device = first_device();
    Glass tinted = rough(0.0, false, true, "tinted");
    tinted.base = dvec3(0.95);
    Glass absorbing = rough(0.0, true, true, "absorbing");
    for (const Glass& glass : {tinted, absorbing}) {
        GlassFurnace f(glass);
        if (glass.volume) {
            f.scene.materials[0].attenuation_color = glm::vec3(0.9f);
            f.scene.materials[0].attenuation_distance = 1.0f;
        }
        RenderSettings settings = furnace_settings("mis");
        const FurnaceCheck c =
            furnace_check(render(device, gpu_scene_for(f.scene, f.camera, settings), settings));
        INFO(glass.label << ": mean " << c.mean << " +- " << c.mean_se << ", worst |z| "
                         << c.worst_z);
        CHECK(c.nan_samples == 0);
        CHECK(c.mean < 1.0 - 10.0 * c.mean_se);
        CHECK(c.worst_z > 4.5);
    }
}

// ---- Estimators agree where glass is in the light's way
// ------------------------------------------

TEST_CASE("every path estimator renders the same mean through rough and smooth glass",
          "[glass][estimators]") {
    // A floor under a glass pane (a mixed material: part diffuse base, part glass) and a quad
    // light above it, under a dim sky: light reaches the floor only through the pane (path
    // continuations), the pane's top by next-event estimation and by paths. The estimators split
    // the work differently, so their means agree only if nothing is counted twice or missed.
    DeviceContext device = first_device();
    for (double roughness : {0.0, 0.3}) {
        Scene scene;
        uint32_t floor = add_material(scene, glm::vec3(0.6f, 0.5f, 0.4f));
        add_quad(scene, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, floor);
        Glass pane = rough(roughness, false, true, "pane");
        pane.base = dvec3(0.9, 0.8, 1.0);
        pane.transmission = 0.8;
        scene.materials.push_back(pane.scene_material());
        add_quad(scene, {-1, 0.5f, -1}, {-1, 0.5f, 1}, {1, 0.5f, 1}, {1, 0.5f, -1},
                 uint32_t(scene.materials.size() - 1));
        uint32_t light = add_material(scene, glm::vec3(0.0f), glm::vec3(8.0f, 7.0f, 6.0f));
        add_quad(scene, {-0.3f, 1.2f, -0.3f}, {0.3f, 1.2f, -0.3f}, {0.3f, 1.2f, 0.3f},
                 {-0.3f, 1.2f, 0.3f}, light);
        Camera camera = looking_down(glm::vec3(0.2f, 2.5f, 0.1f), glm::radians(60.0f));
        RenderSettings settings = image_settings(8, 8, 256);
        settings.sky = glm::vec3(0.2f);
        settings.sky_light = true;
        settings.max_depth = 4;
        GpuSceneData data = gpu_scene_for(scene, camera, settings);
        REQUIRE(data.transmission);
        std::vector<std::pair<std::string, Renders>> results;
        for (const char* estimator : {"mis", "light-area", "bsdf", "hemisphere-cosine"}) {
            settings.estimator = estimator;
            results.emplace_back(estimator, independent_renders(device, data, settings, 10, 700));
        }
        const Renders& reference = results[0].second;
        for (const auto& [name, r] : results) {
            INFO("roughness " << roughness << ", " << name << ": (" << r.mean.x << ", " << r.mean.y
                              << ", " << r.mean.z << ") +- (" << r.standard_error.x << ", "
                              << r.standard_error.y << ", " << r.standard_error.z
                              << ") against mis (" << reference.mean.x << ", " << reference.mean.y
                              << ", " << reference.mean.z << ")");
            CHECK(r.nan_samples == 0);
            CHECK(r.non_finite_pixels == 0);
            for (int c = 0; c < 3; ++c) {
                const double se = std::hypot(r.standard_error[c], reference.standard_error[c]);
                CHECK(std::abs(r.mean[c] - reference.mean[c]) <= 4.5 * se);
                CHECK(r.standard_error[c] < 0.05 * reference.mean[c]);  // not vacuous
            }
        }
    }
}

// ---- A smooth glass slab above a Lambertian floor under the sky: the closed form ----------------

namespace {

// The cosine-weighted hemispherical transmittance of a smooth slab of relative index eta without
// absorption, T̄ = 2 ∫ T_s(μ) μ dμ with T_s = (1 − R)/(1 + R), the sum over the slab's internal
// reflections of a single interface's Fresnel reflectance R (docs/MATERIALS.md, "The slab").
double slab_transmittance(double eta) {
    const int n = 200000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        const double mu = (i + 0.5) / n, R = fresnel_reference(mu, eta);
        sum += 2.0 * (1.0 - R) / (1.0 + R) * mu / n;
    }
    return sum;
}

}  // namespace

TEST_CASE("a smooth glass slab over a Lambertian floor under the sky: the floor's closed form",
          "[glass][slab]") {
    // Floor radiance L = ρ/π ∫ (T_s L_sky + R_s L) cosθ dω = ρ (T̄ + (1 − T̄) L) for a uniform sky of
    // radiance 1, so L = ρ T̄ / (1 − ρ (1 − T̄)): the light the slab lets through plus what it
    // sends back between floor and slab, every order. The slab (2000 wide, 0.1 thick, 0.5 above
    // the floor) is infinite for the camera between them, looking down.
    const glm::dvec3 rho(0.5, 0.7, 0.3);
    const double T = slab_transmittance(1.5);
    const glm::dvec3 exact = rho * T / (1.0 - rho * (1.0 - T));
    Scene scene;
    const float w = 1000.0f;
    uint32_t floor = add_material(scene, glm::vec3(rho));
    add_quad(scene, {-w, 0, -w}, {-w, 0, w}, {w, 0, w}, {w, 0, -w}, floor);
    scene.materials.push_back(rough(0.0, true, true, "slab").scene_material());
    const uint32_t glass = uint32_t(scene.materials.size() - 1);
    const float y0 = 0.5f, y1 = 0.6f;
    // The box's six faces, counter-clockwise seen from outside.
    add_quad(scene, {-w, y1, -w}, {-w, y1, w}, {w, y1, w}, {w, y1, -w}, glass);    // top, +y
    add_quad(scene, {-w, y0, -w}, {w, y0, -w}, {w, y0, w}, {-w, y0, w}, glass);    // bottom, −y
    add_quad(scene, {-w, y0, w}, {w, y0, w}, {w, y1, w}, {-w, y1, w}, glass);      // +z
    add_quad(scene, {-w, y0, -w}, {-w, y1, -w}, {w, y1, -w}, {w, y0, -w}, glass);  // −z
    add_quad(scene, {w, y0, -w}, {w, y1, -w}, {w, y1, w}, {w, y0, w}, glass);      // +x
    add_quad(scene, {-w, y0, -w}, {-w, y0, w}, {-w, y1, w}, {-w, y1, -w}, glass);  // −x
    Camera camera = looking_down(glm::vec3(0.0f, 0.25f, 0.0f), glm::radians(30.0f));
    DeviceContext device = first_device();
    RenderSettings settings = image_settings(8, 8, 64);
    settings.sky = glm::vec3(1.0f);
    settings.sky_light = true;
    settings.max_depth = MCRT_MAX_PATH_DEPTH;
    settings.rr_depth = MCRT_MAX_PATH_DEPTH;
    GpuSceneData data = gpu_scene_for(scene, camera, settings);
    for (const char* estimator : {"mis", "bsdf", "light-area"}) {
        settings.estimator = estimator;
        Renders r = independent_renders(device, data, settings, 10, 900);
        check_unbiased(r, exact, std::string("slab, ") + estimator);
        CHECK(r.non_finite_pixels == 0);
        for (int c = 0; c < 3; ++c) CHECK(r.standard_error[c] < 0.01 * exact[c]);  // not vacuous
    }
}

TEST_CASE("transmissionTexture scales transmissionFactor by its R channel", "[glass][textures]") {
    // A thin smooth pane over a floor under the sky, seen from above. A pane of factor 1 whose
    // 1×1 texture holds R = 128 must render as an untextured pane of factor 128/255, and one whose
    // texel is R = 0 as an opaque one (factor 0); the two untextured panes differ by far more than
    // the renders' noise, so the check can fail.
    auto pane_scene = [](float factor, int texel) {
        Scene scene;
        const float w = 1000.0f;
        uint32_t floor = add_material(scene, glm::vec3(0.5f, 0.7f, 0.3f));
        add_quad(scene, {-w, 0, -w}, {-w, 0, w}, {w, 0, w}, {w, 0, -w}, floor);
        Glass g = rough(0.0, false, true, "pane");
        g.transmission = factor;
        scene.materials.push_back(g.scene_material());
        const uint32_t pane = uint32_t(scene.materials.size() - 1);
        add_quad(scene, {-w, 0.5f, -w}, {-w, 0.5f, w}, {w, 0.5f, w}, {w, 0.5f, -w}, pane);
        if (texel >= 0) {
            TextureImage image;
            image.name = "transmission";
            image.width = image.height = 1;
            image.rgba = {uint8_t(texel), 0, 0, 255};
            scene.images.push_back(image);
            TextureRef& ref = scene.materials[pane].transmission_texture;
            ref.image = 0;
            ref.linear = false;
            scene.texcoords.assign(scene.positions.size(), glm::vec4(0.5f, 0.5f, 0.0f, 0.0f));
        }
        return scene;
    };
    Camera camera = looking_down(glm::vec3(0.0f, 1.0f, 0.0f), glm::radians(30.0f));
    DeviceContext device = first_device();
    RenderSettings settings = image_settings(8, 8, 64);
    settings.sky = glm::vec3(1.0f);
    settings.sky_light = true;
    settings.max_depth = 16;
    settings.rr_depth = 16;
    settings.estimator = "mis";
    auto renders = [&](const Scene& scene) {
        return independent_renders(device, gpu_scene_for(scene, camera, settings), settings, 10,
                                   1300);
    };
    auto agree = [](const Renders& a, const Renders& b, const std::string& what) {
        INFO(what << ": (" << a.mean.x << ", " << a.mean.y << ", " << a.mean.z << ") against ("
                  << b.mean.x << ", " << b.mean.y << ", " << b.mean.z << ")");
        CHECK(a.nan_samples == 0);
        for (int c = 0; c < 3; ++c) {
            const double se = std::sqrt(a.standard_error[c] * a.standard_error[c] +
                                        b.standard_error[c] * b.standard_error[c]);
            CHECK(std::abs(a.mean[c] - b.mean[c]) <= 4.5 * se);
        }
    };
    const Renders half_textured = renders(pane_scene(1.0f, 128));
    const Renders half = renders(pane_scene(128.0f / 255.0f, -1));
    const Renders none_textured = renders(pane_scene(1.0f, 0));
    const Renders none = renders(pane_scene(0.0f, -1));
    agree(half_textured, half, "factor 1 × texel 128/255 against factor 128/255");
    agree(none_textured, none, "factor 1 × texel 0 against factor 0");
    for (int c = 0; c < 3; ++c) {
        const double se = std::sqrt(half.standard_error[c] * half.standard_error[c] +
                                    none.standard_error[c] * none.standard_error[c]);
        CHECK(std::abs(half.mean[c] - none.mean[c]) > 20.0 * se);  // not vacuous
    }
}
