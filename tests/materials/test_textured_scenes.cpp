// The analytic textured glTF scenes of tests/data/textured (scripts/scenes/make_textured_tests.py)
// against their exact values (EXPECTED.json, EXPECTED.md says how each view is used): imported
// from the files, so that the import of every texture feature is checked with the kernels.
//  - labelled floor views: each labelled pixel is its texel's ratio × the untextured twin's
//    pixel, exact to rounding (the same seed draws the same samples in both);
//  - labelled light views (the light seen from below): each labelled pixel is its radiance (a
//    blended light's, a coin per sample, by its mean over the label's pixels);
//  - image means: within the light-area estimator's standard error over independent renders.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"
#include "scene/gltf_import.h"

using namespace mcrt;
using namespace mcrt::test;
using nlohmann::json;

namespace {

const std::string kDir = std::string(MCRT_TEST_DATA) + "/textured/";

const json& expected() {
    static const json e = [] {
        std::ifstream in(kDir + "EXPECTED.json");
        return json::parse(in);
    }();
    return e;
}

struct View {
    Scene scene;
    Camera camera;
    GpuSceneData data;
};

View load_view(const std::string& file, int camera, const RenderSettings& settings) {
    View v;
    v.scene = load_gltf(kDir + file, nullptr);
    REQUIRE(size_t(camera) < v.scene.cameras.size());
    v.camera = v.scene.cameras[size_t(camera)];
    v.data = gpu_scene_for(v.scene, v.camera, settings);
    return v;
}

RenderSettings view_settings(const json& view) {
    RenderSettings settings = image_settings(view["resolution"][0], view["resolution"][1], 16);
    settings.estimator = "light-area";
    settings.seed = 7;
    return settings;
}

glm::dvec3 vec(const json& a) {
    return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
}

// Every labelled pixel of the view: its legend's ratio to the twin's pixel, or its radiance.
void check_labels(const std::string& name, const json& scene, const json& view) {
    DeviceContext device = first_device();
    const RenderSettings settings = view_settings(view);
    const int camera = view["camera"];
    View textured = load_view(scene["file"], camera, settings);
    RenderResult image = render(device, textured.data, settings);
    RenderResult twin;
    const bool ratio = view.contains("untextured_twin");
    if (ratio) {
        const json& other = expected()["scenes"][view["untextured_twin"].get<std::string>()];
        View plain = load_view(other["file"], camera, settings);
        twin = render(device, plain.data, settings);
    }
    const json& legend = view["legend"];
    // A blended surface seen directly is a coin per sample (stochastic transparency): its pixels
    // are checked by their mean per label, within that mean's standard error, the others exactly.
    const bool stochastic = name.rfind("blend", 0) == 0 && !ratio;
    std::map<std::string, std::vector<glm::dvec3>> by_label;
    int checked = 0;
    for (int j = 0; j < settings.height; ++j) {
        const std::string row = view["labels"][size_t(j)];
        for (int i = 0; i < settings.width; ++i) {
            const std::string label(1, row[size_t(i)]);
            if (label == "." || !legend.contains(label)) continue;
            const size_t at = 3 * (size_t(j) * settings.width + size_t(i));
            ++checked;
            if (stochastic) {
                by_label[label].push_back(glm::dvec3(image.image.rgb[at], image.image.rgb[at + 1],
                                                     image.image.rgb[at + 2]));
                continue;
            }
            for (int c = 0; c < 3; ++c) {
                INFO(name << " camera " << camera << " pixel " << i << ", " << j << " label "
                          << label << " channel " << c);
                const float got = image.image.rgb[at + size_t(c)];
                if (ratio) {
                    const double want = legend[label]["ratio"][size_t(c)].get<double>() *
                                        twin.image.rgb[at + size_t(c)];
                    CHECK(got == Approx(want).epsilon(2e-5).margin(1e-9));
                } else {
                    const double want = legend[label]["radiance"][size_t(c)].get<double>();
                    CHECK(got == Approx(want).epsilon(1e-5).margin(1e-6));
                }
            }
        }
    }
    for (const auto& [label, values] : by_label) {
        glm::dvec3 mean(0.0), var(0.0);
        for (const glm::dvec3& v : values) mean += v / double(values.size());
        for (const glm::dvec3& v : values)
            var += (v - mean) * (v - mean) / double(values.size() - 1);
        const glm::dvec3 want = vec(legend[label]["radiance"]);
        for (int c = 0; c < 3; ++c) {
            INFO(name << " camera " << camera << " label " << label << " channel " << c << ": mean "
                      << mean[c] << " over " << values.size() << " pixels, exact " << want[c]);
            CHECK(std::abs(mean[c] - want[c]) <=
                  4.5 * std::sqrt(var[c] / double(values.size())) + 1e-6);
        }
    }
    CHECK(checked > 100);
}

// The image mean against the exact one, within 4.5 standard errors of independent renders.
void check_mean(const std::string& name, const json& scene, const json& view) {
    DeviceContext device = first_device();
    RenderSettings settings = view_settings(view);
    settings.width = 32;  // the mean of a 64 × 64 image is that of its 32 × 32 halving
    settings.height = 32;
    View v = load_view(scene["file"], view["camera"], settings);
    Renders r = independent_renders(device, v.data, settings, 10, 500);
    check_unbiased(r, vec(view["image_mean"]), name);
    CHECK(r.standard_error.x < 0.03 * vec(view["image_mean"]).x);
}

}  // namespace

TEST_CASE("textured glTF scenes: every labelled pixel is its texel's ratio or its radiance",
          "[textures][gltf]") {
    for (const auto& [name, scene] : expected()["scenes"].items())
        for (const json& view : scene["views"])
            if (view.contains("labels")) check_labels(name, scene, view);
}

TEST_CASE("textured glTF scenes: image means within the estimator's standard error",
          "[textures][gltf][analytic]") {
    for (const auto& [name, scene] : expected()["scenes"].items())
        for (const json& view : scene["views"])
            if (view.contains("image_mean") && view.contains("untextured_twin"))
                check_mean(name, scene, view);
}
