// Textured surfaces against exact answers, on scenes built in code (the same features read from
// glTF files: test_textured_scenes.cpp):
//  - a textured floor under a polygon light renders, pixel by pixel, its untextured image times
//    the texel under the pixel (common random numbers: the two renders draw the same samples, so
//    the ratio is exact to rounding), for each wrap mode, NEAREST, KHR_texture_transform and the
//    second texture-coordinate set;
//  - an emissive-textured light, a light cut by MASK and a BLEND light and occluder at alpha 0.5
//    against Lambert's formula over what remains, within the estimators' own standard errors;
//  - a normal texture tilted 60° from the view under the sky: a Lambertian floor gives the tilted
//    plane's ρ (1 + cosθ)/2, and a smooth metal reflects the sky, never black.
#include <catch2/catch.hpp>
#include <cmath>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/renderer.h"
#include "scene/texture_lookup.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

constexpr int kRenders = 10;
constexpr uint32_t kFirstSeed = 3000;

// A w × h image of sRGB-encoded texels given by texel(i, j) → RGBA bytes.
template <typename F>
uint32_t add_image(Scene& s, uint32_t w, uint32_t h, F texel) {
    TextureImage image;
    image.name = "image " + std::to_string(s.images.size());
    image.width = w;
    image.height = h;
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            const glm::u8vec4 c = texel(i, j);
            image.rgba.insert(image.rgba.end(), {c.r, c.g, c.b, c.a});
        }
    s.images.push_back(image);
    return uint32_t(s.images.size() - 1);
}

// A 4 × 4 checker of distinct colours (every texel differs from its neighbours).
uint32_t add_checker(Scene& s) {
    return add_image(s, 4, 4, [](uint32_t i, uint32_t j) {
        return glm::u8vec4(40 + 50 * i, 230 - 45 * j, (i + j) % 2 ? 255 : 60, 255);
    });
}

// Texture coordinates for every corner of the scene so far: TEXCOORD_0 = uv(p), TEXCOORD_1 its
// mirror image (or the reverse with `second`).
template <typename F>
void set_texcoords(Scene& s, F uv, bool second = false) {
    s.texcoords.clear();
    for (const glm::vec3& p : s.positions) {
        const glm::vec2 t = uv(p), junk(-7.25f, 3.5f);
        s.texcoords.push_back(second ? glm::vec4(junk, t) : glm::vec4(t, junk));
    }
}

RenderSettings small_settings() {
    RenderSettings settings = image_settings(24, 24, 16);
    settings.estimator = "light-area";
    return settings;
}

// Floor point under film point (x, y) of the camera (the plane y = 0).
glm::dvec3 floor_point(const gpu::CameraGpu& cam, double x, double y) {
    const glm::dvec3 eye(cam.eye.x, cam.eye.y, cam.eye.z);
    const glm::dvec3 d = glm::dvec3(cam.forward.x, cam.forward.y, cam.forward.z) +
                         x * glm::dvec3(cam.right.x, cam.right.y, cam.right.z) +
                         y * glm::dvec3(cam.up.x, cam.up.y, cam.up.z);
    return eye + (-eye.y / d.y) * d;
}

// Renders the plane scene with the floor's base colour texture `ref` (the floor's corners
// mapped by floor_uv) and without, and checks every pixel whose footprint lies in one texel:
// textured = untextured × that texel. Returns how many pixels were checked.
template <typename F>
int check_texel_ratios(TextureRef ref, F floor_uv, bool second_set = false) {
    DeviceContext device = first_device();
    PlaneScene plain;
    PlaneScene textured;
    const uint32_t image = add_checker(textured.scene);
    ref.image = int32_t(image);
    ref.srgb = true;
    ref.linear = false;
    ref.texcoord = second_set ? 1 : 0;
    textured.scene.materials[0].base_color_texture = ref;
    set_texcoords(textured.scene, floor_uv, second_set);

    RenderSettings settings = small_settings();
    RenderResult a = render(device, gpu_scene_for(plain.scene, plain.camera, settings), settings);
    GpuSceneData data = gpu_scene_for(textured.scene, textured.camera, settings);
    REQUIRE(data.textured);
    RenderResult b = render(device, data, settings);

    const gpu::CameraGpu cam = make_gpu_camera(textured.camera, settings.width, settings.height);
    const TextureImage& img = textured.scene.images[image];
    int checked = 0;
    for (int j = 0; j < settings.height; ++j)
        for (int i = 0; i < settings.width; ++i) {
            // The texel at the footprint's corners and centre, as the kernels look it up.
            glm::vec4 texel[5];
            const double xs[5] = {0, 1, 0, 1, 0.5}, ys[5] = {0, 0, 1, 1, 0.5};
            for (int k = 0; k < 5; ++k) {
                const double x = 2.0 * (i + xs[k]) / settings.width - 1.0;
                const double y = 1.0 - 2.0 * (j + ys[k]) / settings.height;
                texel[k] = texture_lookup(img, ref, floor_uv(glm::vec3(floor_point(cam, x, y))));
            }
            bool one = true;
            for (int k = 0; k < 4; ++k) one = one && texel[k] == texel[4];
            if (!one) continue;
            for (int c = 0; c < 3; ++c) {
                const size_t at = 3 * (size_t(j) * settings.width + i) + size_t(c);
                if (!(a.image.rgb[at] > 0.0f)) continue;
                INFO("pixel " << i << ", " << j << " channel " << c);
                CHECK(b.image.rgb[at] == Approx(a.image.rgb[at] * texel[4][c]).epsilon(1e-5));
            }
            ++checked;
        }
    return checked;
}

glm::vec2 floor_uv_wide(const glm::vec3& p) { return {1.8f * p.x + 0.5f, 1.8f * p.z + 0.5f}; }

}  // namespace

TEST_CASE("a NEAREST sRGB checker: each pixel is its texel's linear albedo times the untextured",
          "[textures]") {
    // REPEAT, CLAMP_TO_EDGE and MIRRORED_REPEAT, each axis alone and mixed, over UVs from
    // about −1.5 to 2.5 (the camera sees |x|, |z| < 1.1).
    const TextureWrap modes[3] = {TextureWrap::Repeat, TextureWrap::ClampToEdge,
                                  TextureWrap::MirroredRepeat};
    for (TextureWrap s : modes)
        for (TextureWrap t : modes) {
            TextureRef ref;
            ref.wrap_s = s;
            ref.wrap_t = t;
            INFO("wrap " << int(s) << ", " << int(t));
            CHECK(check_texel_ratios(ref, floor_uv_wide) > 60);
        }
}

TEST_CASE("KHR_texture_transform and TEXCOORD_1 move the checker as the host's lookup does",
          "[textures]") {
    TextureRef ref;
    // Offset, rotation by 90° and scale 2 (KHR_texture_transform: T · R · S).
    const float c = 0.0f, s = 1.0f, sx = 2.0f, sy = 2.0f, ox = 0.25f, oy = -0.5f;
    ref.row_u = {c * sx, s * sy, ox};
    ref.row_v = {-s * sx, c * sy, oy};
    CHECK(check_texel_ratios(ref, [](const glm::vec3& p) { return glm::vec2(p.x, p.z); }) > 30);
    CHECK(check_texel_ratios(TextureRef{}, floor_uv_wide, /*second_set=*/true) > 60);
}

TEST_CASE("MASK on the floor: holes show what is behind (nothing), the rest is unchanged",
          "[textures]") {
    DeviceContext device = first_device();
    PlaneScene plain, masked;
    const uint32_t image = add_image(masked.scene, 2, 2, [](uint32_t i, uint32_t j) {
        return glm::u8vec4(255, 255, 255, (i + j) % 2 ? 0 : 255);
    });
    Material& floor = masked.scene.materials[0];
    floor.alpha_mode = AlphaMode::Mask;
    floor.base_color_texture.image = int32_t(image);
    floor.base_color_texture.srgb = true;
    floor.base_color_texture.linear = false;
    set_texcoords(masked.scene, [](const glm::vec3& p) { return glm::vec2(p.x, p.z); });
    RenderSettings settings = small_settings();
    RenderResult a = render(device, gpu_scene_for(plain.scene, plain.camera, settings), settings);
    RenderResult b = render(device, gpu_scene_for(masked.scene, masked.camera, settings), settings);
    const gpu::CameraGpu cam = make_gpu_camera(masked.camera, settings.width, settings.height);
    int holes = 0, kept = 0;
    for (int j = 0; j < settings.height; ++j)
        for (int i = 0; i < settings.width; ++i) {
            float alpha[5];
            const double xs[5] = {0, 1, 0, 1, 0.5}, ys[5] = {0, 0, 1, 1, 0.5};
            for (int k = 0; k < 5; ++k) {
                const glm::dvec3 p = floor_point(cam, 2.0 * (i + xs[k]) / settings.width - 1.0,
                                                 1.0 - 2.0 * (j + ys[k]) / settings.height);
                alpha[k] = texture_lookup(masked.scene.images[image], floor.base_color_texture,
                                          glm::vec2(p.x, p.z))
                               .w;
            }
            bool one = true;
            for (int k = 0; k < 4; ++k) one = one && alpha[k] == alpha[4];
            if (!one) continue;
            const size_t at = 3 * (size_t(j) * settings.width + i);
            if (alpha[4] == 0.0f) {
                CHECK(b.image.rgb[at] == 0.0f);
                ++holes;
            } else {
                CHECK(b.image.rgb[at] == a.image.rgb[at]);
                ++kept;
            }
        }
    CHECK(holes > 50);
    CHECK(kept > 50);
}

namespace {

// The plane scene's quad light (corners a, b, c, d, facing −Y) split into n × n squares, square
// (i, j) at u in [i/n, (i+1)/n) from a toward b, v in [j/n, (j+1)/n) from a toward d.
std::vector<glm::dvec3> light_square(const PolygonLight& l, int n, int i, int j) {
    const glm::dvec3 a = l.polygon[0], du = (l.polygon[1] - a) / double(n),
                     dv = (l.polygon[3] - a) / double(n);
    const glm::dvec3 o = a + double(i) * du + double(j) * dv;
    return {o, o + du, o + du + dv, o + dv};
}

// The exact image of the plane scene's floor lit by the polygons `lit` (radiance per polygon).
std::vector<double> exact_floor(const PlaneScene& ps, int w, int h,
                                const std::vector<PolygonLight>& lit) {
    return exact_plane_image(ps.camera, w, h, [&](glm::dvec3 p) {
        glm::dvec3 v(0.0);
        for (const PolygonLight& l : lit)
            v += ps.albedo / M_PI * l.Le * lambert_irradiance(l.polygon, p, {0, 1, 0}, 1.0);
        return v;
    });
}

// The quad light's corners as texture coordinates: a → (0, 0), b → (1, 0), d → (0, 1), for
// every corner of the scene's triangles (the floor's and the triangle light's get (0, 0)).
void map_quad_light(Scene& s, const PolygonLight& l) {
    const glm::dvec3 a = l.polygon[0], du = l.polygon[1] - a, dv = l.polygon[3] - a;
    set_texcoords(s, [&](const glm::vec3& p) {
        const glm::dvec3 q = glm::dvec3(p) - a;
        if (std::abs(p.y - float(a.y)) > 1e-6f) return glm::vec2(0.0f);
        return glm::vec2(float(glm::dot(q, du) / glm::dot(du, du)),
                         float(glm::dot(q, dv) / glm::dot(dv, dv)));
    });
}

// Every direct-light estimator (light-area, light-solid-angle, bsdf, hemisphere-*, mis) on
// `scene` against the exact floor image's mean.
void check_estimators(const PlaneScene& ps, const std::vector<double>& exact_img,
                      const std::string& what) {
    DeviceContext device = first_device();
    RenderSettings settings = small_settings();
    settings.width = 16;
    settings.height = 16;
    GpuSceneData data = gpu_scene_for(ps.scene, ps.camera, settings);
    REQUIRE(data.textured);
    const glm::dvec3 exact = image_mean(exact_img);
    for (const EstimatorCase& v : estimator_cases(kUsesLights, kUsesSky)) {
        if (v.heuristic != RenderSettings().mis_heuristic) continue;
        v.apply(settings);
        settings.spp = v.uses(kUsesLightSelection) ? 64 : 1024;
        Renders r = independent_renders(device, data, settings, kRenders, kFirstSeed);
        check_unbiased(r, exact, what + " / " + v.label());
        CHECK(r.standard_error.x < 0.05 * exact.x);
    }
}

}  // namespace

TEST_CASE("an emissive-textured light lights the floor as its four texels would",
          "[textures][analytic]") {
    PlaneScene ps;
    const PolygonLight quad = ps.lights[0];
    // 2 × 2 NEAREST texels, sRGB: the light's four squares emit Le × their linear values.
    const glm::u8vec4 texels[4] = {
        {255, 255, 255, 255}, {128, 64, 32, 255}, {0, 0, 0, 255}, {200, 230, 90, 255}};
    const uint32_t image =
        add_image(ps.scene, 2, 2, [&](uint32_t i, uint32_t j) { return texels[2 * j + i]; });
    Material& light = ps.scene.materials[ps.scene.triangle_material[2]];
    light.emissive_texture.image = int32_t(image);
    light.emissive_texture.srgb = true;
    light.emissive_texture.linear = false;
    map_quad_light(ps.scene, quad);
    std::vector<PolygonLight> lit = {ps.lights[1]};
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const glm::u8vec4 t = texels[2 * j + i];
            lit.push_back({light_square(quad, 2, i, j),
                           quad.Le * glm::dvec3(srgb_to_linear(t.r), srgb_to_linear(t.g),
                                                srgb_to_linear(t.b))});
        }
    check_estimators(ps, exact_floor(ps, 16, 16, lit), "emissive texture");
}

TEST_CASE("a light cut by MASK: its holes neither emit nor block", "[textures][analytic]") {
    PlaneScene ps;
    const PolygonLight quad = ps.lights[0];
    // A 4 × 4 mask, cutoff 0.5: alpha 0 (cut), 100 (below), 200 and 255 (kept).
    auto alpha = [](uint32_t i, uint32_t j) -> uint8_t {
        const uint8_t values[4] = {0, 100, 200, 255};
        return values[(3 * i + j) % 4];
    };
    const uint32_t image = add_image(ps.scene, 4, 4, [&](uint32_t i, uint32_t j) {
        return glm::u8vec4(255, 255, 255, alpha(i, j));
    });
    Material& light = ps.scene.materials[ps.scene.triangle_material[2]];
    light.alpha_mode = AlphaMode::Mask;
    light.base_color_texture.image = int32_t(image);
    light.base_color_texture.srgb = true;
    light.base_color_texture.linear = false;
    map_quad_light(ps.scene, quad);
    std::vector<PolygonLight> lit = {ps.lights[1]};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            if (alpha(uint32_t(i), uint32_t(j)) / 255.0f >= 0.5f)
                lit.push_back({light_square(quad, 4, i, j), quad.Le});
    check_estimators(ps, exact_floor(ps, 16, 16, lit), "masked light");
}

TEST_CASE("BLEND at alpha 0.5 halves a light, as a light and as an occluder",
          "[textures][analytic]") {
    {
        PlaneScene ps;
        Material& light = ps.scene.materials[ps.scene.triangle_material[2]];
        light.alpha_mode = AlphaMode::Blend;
        light.alpha = 0.5f;
        set_texcoords(ps.scene, [](const glm::vec3&) { return glm::vec2(0.0f); });
        std::vector<PolygonLight> lit = {ps.lights[1], ps.lights[0]};
        lit[1].Le *= 0.5;
        check_estimators(ps, exact_floor(ps, 16, 16, lit), "blended light");
    }
    {
        // A black plane of alpha 0.5 just below the quad light, wider than it by more than the
        // parallax of its gap: every path from the light to the floor crosses it once.
        PlaneScene ps;
        const uint32_t veil = add_material(ps.scene, glm::vec3(0.0f));
        ps.scene.materials[veil].alpha_mode = AlphaMode::Blend;
        ps.scene.materials[veil].alpha = 0.5f;
        ps.scene.materials[veil].double_sided = true;
        const float y = 0.999f;
        add_quad(ps.scene, {0.79f, y, -0.27f}, {1.32f, y, -0.27f}, {1.32f, y, 0.27f},
                 {0.79f, y, 0.27f}, veil);
        set_texcoords(ps.scene, [](const glm::vec3&) { return glm::vec2(0.0f); });
        std::vector<PolygonLight> lit = {ps.lights[1], ps.lights[0]};
        lit[1].Le *= 0.5;
        check_estimators(ps, exact_floor(ps, 16, 16, lit), "blended occluder");
    }
}

namespace {

// A floor (y = 0, facing +Y) of one material whose 1 × 1 normal texture tilts the shading normal
// 60° toward +X (about the vertex normal +Y and the tangent +X), under the sky light of radiance
// 1, seen from straight above: the view is 60° from the bent normal, so its mirror direction
// about it lies 30° below the floor.
RenderResult tilted_floor_under_sky(const Material& material, uint32_t seed) {
    Scene s;
    s.materials.push_back(material);
    add_quad(s, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, 0);
    // (sin 60°, 0, cos 60°) as texels: (238, 128, 191).
    const uint32_t image =
        add_image(s, 1, 1, [](uint32_t, uint32_t) { return glm::u8vec4(238, 128, 191, 255); });
    s.materials[0].normal_texture.image = int32_t(image);
    set_texcoords(s, [](const glm::vec3& p) { return glm::vec2(p.x, p.z); });
    s.normals.assign(s.positions.size(), glm::vec3(0, 1, 0));
    s.tangents.assign(s.positions.size(), glm::vec4(1, 0, 0, 1));
    RenderSettings settings = small_settings();
    settings.estimator = "mis";
    settings.sky = glm::vec3(1.0f);
    settings.sky_light = true;
    settings.spp = 64;
    settings.seed = seed;
    const Camera camera = looking_down(glm::vec3(0, 3, 0), glm::radians(40.0f));
    GpuSceneData data = gpu_scene_for(s, camera, settings);
    REQUIRE(data.textured);
    return render(first_device(), data, settings);
}

}  // namespace

TEST_CASE("a normal texture tilted 60° from the view: a mirror reflects the sky, not black",
          "[textures][normal]") {
    // Lambertian (ρ = 0.5): the sky above the floor seen by a surface tilted θ from it gives
    // E = π L (1 + cosθ)/2 (the isotropic sky on a tilted plane), so L_o = ρ (1 + cosθ)/2, with
    // cosθ the texel's normalised z. Directions above the bent normal but below the floor carry
    // no light.
    const glm::dvec3 c(238 / 255.0 * 2 - 1, 128 / 255.0 * 2 - 1, 191 / 255.0 * 2 - 1);
    const double exact = 0.5 * (1.0 + c.z / glm::length(c)) / 2.0;
    Material lambert;
    lambert.albedo = glm::vec3(0.5f);
    const RenderResult l = tilted_floor_under_sky(lambert, 11);
    // One channel: the three are the same numbers (a grey floor under a white sky).
    double sum = 0, variance = 0;
    for (size_t i = 1; i < l.image.rgb.size(); i += 3) {
        sum += l.image.rgb[i];
        variance += l.image.variance[i];
    }
    const double n = double(l.image.rgb.size() / 3), mean = sum / n, se = std::sqrt(variance) / n;
    INFO("Lambertian: mean " << mean << " +- " << se << " against " << exact);
    CHECK(l.nan_samples == 0);
    CHECK(std::abs(mean - exact) < 4.5 * se);
    CHECK(se < 0.01 * exact);

    // A smooth white metal (F = 1): the bent normal is turned toward the floor's until the view's
    // mirror direction just clears the floor, and every pixel sees the sky in it. Without that
    // turn the mirror direction points into the floor and every pixel is black.
    Material metal;
    metal.albedo = glm::vec3(1.0f);
    metal.metallic = 1.0f;
    metal.roughness = 0.0f;
    metal.specular = 1.0f;
    const RenderResult m = tilted_floor_under_sky(metal, 12);
    float darkest = 1e30f;
    double metal_sum = 0;
    for (float v : m.image.rgb) {
        darkest = std::min(darkest, v);
        metal_sum += v;
    }
    INFO("metal: darkest pixel " << darkest << ", mean " << metal_sum / m.image.rgb.size());
    CHECK(m.nan_samples == 0);
    CHECK(darkest > 0.5f);
    CHECK(metal_sum / m.image.rgb.size() > 0.9);
}
