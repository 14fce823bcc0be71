// Single-sided surfaces (glTF 2.0 sec. 3.9.2, `doubleSided` false): a surface seen from behind is
// not there for camera, path and shadow rays alike, unless it transmits (DESIGN.md "Radiometric
// contract"); kernels built with -D MCRT_SINGLE_SIDED only for a scene that has such a surface.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "analytic_scenes.h"
#include "bvh/bvh.h"
#include "device_support.h"
#include "independent_renders.h"
#include "render/gpu_scene.h"
#include "render/plan.h"
#include "render/renderer.h"
#include "scene_builders.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

bool culls(const GpuSceneData& data) {
    return make_render_plan(RenderSettings{}, data).program_options.find("-D MCRT_SINGLE_SIDED") !=
           std::string::npos;
}

// Quad in the plane y = h over [-s, s]², facing +Y (up) or −Y.
void add_level_quad(Scene& s, float h, float size, bool up, uint32_t material) {
    const glm::vec3 a(-size, h, -size), b(-size, h, size), c(size, h, size), d(size, h, -size);
    if (up)
        add_quad(s, a, b, c, d, material);  // counter-clockwise seen from above
    else
        add_quad(s, a, d, c, b, material);
}

// A smooth glass volume (KHR_materials_transmission 1, _volume, ior 1.5), single-sided as glTF's
// default.
Material glass() {
    Material m;
    m.albedo = glm::vec3(1.0f);
    m.metallic = 0.0f;
    m.roughness = 0.0f;
    m.specular = 1.0f;
    m.transmission = 1.0f;
    m.volume = true;
    return m;
}

// Every pixel of the render, channel by channel.
std::vector<float> pixels(const DeviceContext& device, const GpuSceneData& data,
                          const RenderSettings& settings) {
    const RenderResult r = render(device, data, settings);
    CHECK(r.nan_samples == 0);
    return std::vector<float>(r.image.rgb.begin(), r.image.rgb.end());
}

// Every value of `image` is `value`'s channel (pixels of three channels).
bool all_equal(const std::vector<float>& image, glm::vec3 value) {
    for (size_t i = 0; i < image.size(); ++i)
        if (std::abs(image[i] - value[int(i % 3)]) > 1e-6f * std::max(1.0f, value[int(i % 3)]))
            return false;
    return true;
}

}  // namespace

TEST_CASE("only a single-sided, non-transmissive triangle is flagged and builds the culling code",
          "[single-sided]") {
    for (int kind = 0; kind < 3; ++kind) {
        Scene s;
        if (kind == 0) add_material(s, glm::vec3(0.5f), glm::vec3(0.0f), true);  // double-sided
        if (kind == 1) add_material(s, glm::vec3(0.5f));                         // single-sided
        if (kind == 2) s.materials.push_back(glass());  // single-sided, transmissive
        add_level_quad(s, 0.0f, 1.0f, true, 0);
        const GpuSceneData data = make_gpu_scene(s, build_bvh(s), Camera{}, 1, 1);
        INFO("kind " << kind);
        CHECK(data.single_sided == (kind == 1));
        CHECK(culls(data) == (kind == 1));
        size_t flagged = 0;
        for (const gpu::TrianglePacket& p : data.packets)
            for (uint32_t index : p.index)
                if (index != MCRT_NO_HIT && (index & MCRT_TRIANGLE_CULLED)) ++flagged;
        CHECK(flagged == (kind == 1 ? 2u : 0u));
    }
}

TEST_CASE("the camera sees a single-sided quad from the front, and what is behind it from behind",
          "[single-sided]") {
    // Looking down at a quad that fills the view, with an emitting backdrop below it; depth 0
    // counts emission at the first hit alone, so each pixel is exactly what the camera ray hits.
    DeviceContext device = first_device();
    const glm::vec3 backdrop_Le(0.25f, 0.5f, 1.0f), quad_Le(2.0f, 2.0f, 2.0f);
    RenderSettings settings = image_settings(8, 8, 4);
    settings.max_depth = 0;
    const Camera camera = looking_down(glm::vec3(0.0f, 2.0f, 0.0f), glm::radians(40.0f));
    struct Case {
        const char* what;
        bool up, double_sided, emits;
        glm::vec3 expected;
    };
    const Case cases[] = {
        {"single-sided, front", true, false, false, glm::vec3(0.0f)},
        {"single-sided, behind", false, false, false, backdrop_Le},
        {"double-sided, behind", false, true, false, glm::vec3(0.0f)},
        {"single-sided emitter, front", true, false, true, quad_Le},
        {"single-sided emitter, behind", false, false, true, backdrop_Le},
    };
    for (const Case& c : cases) {
        Scene s;
        const uint32_t backdrop = add_material(s, glm::vec3(0.5f), backdrop_Le, true);
        const uint32_t quad =
            add_material(s, glm::vec3(0.5f), c.emits ? quad_Le : glm::vec3(0.0f), c.double_sided);
        add_level_quad(s, -1.0f, 10.0f, true, backdrop);
        add_level_quad(s, 0.0f, 2.0f, c.up, quad);
        const GpuSceneData data = gpu_scene_for(s, camera, settings);
        const std::vector<float> image = pixels(device, data, settings);
        INFO(c.what << ": first pixel (" << image[0] << ", " << image[1] << ", " << image[2]
                    << ")");
        CHECK(all_equal(image, c.expected));
    }
}

TEST_CASE(
    "a single-sided occluder facing away from the point does not shadow it, for every "
    "strategy alike",
    "[single-sided][estimators]") {
    // A floor lit by a quad light 2 above it; between them, 1 above the floor, a larger
    // single-sided quad. The camera, below the quad, sees only the floor. Facing up (away from
    // the floor), the quad is absent for the floor's shadow rays and BSDF-sampled rays alike: the
    // image is that of the scene without it, for light-area, bsdf and mis within their standard
    // errors. Facing down it shadows the floor. Direct light (depth 1) isolates visibility.
    DeviceContext device = first_device();
    RenderSettings settings = image_settings(8, 8, 64);
    settings.max_depth = 1;
    const Camera camera = looking_down(glm::vec3(0.0f, 0.9f, 0.0f), glm::radians(90.0f));
    auto scene = [](int occluder) {  // 0: none, 1: facing away from the floor, 2: facing it
        Scene s;
        const uint32_t floor = add_material(s, glm::vec3(0.5f, 0.6f, 0.7f));
        const uint32_t light = add_material(s, glm::vec3(0.0f), glm::vec3(4.0f, 3.0f, 2.0f));
        add_level_quad(s, 0.0f, 3.0f, true, floor);
        add_level_quad(s, 2.0f, 0.5f, false, light);
        if (occluder > 0) {
            const uint32_t block = add_material(s, glm::vec3(0.5f));
            add_level_quad(s, 1.0f, 1.5f, occluder == 1, block);
        }
        return s;
    };
    std::vector<Renders> open, away, facing;
    const char* estimators[] = {"light-area", "bsdf", "mis"};
    for (const char* estimator : estimators) {
        settings.estimator = estimator;
        const GpuSceneData without = gpu_scene_for(scene(0), camera, settings);
        const GpuSceneData with_away = gpu_scene_for(scene(1), camera, settings);
        const GpuSceneData with_facing = gpu_scene_for(scene(2), camera, settings);
        REQUIRE(culls(with_away));
        open.push_back(independent_renders(device, without, settings, 10, 300));
        away.push_back(independent_renders(device, with_away, settings, 10, 300));
        facing.push_back(independent_renders(device, with_facing, settings, 10, 300));
    }
    for (size_t e = 0; e < 3; ++e) {
        const Renders &o = open[e], &a = away[e], &f = facing[e], &ref = away[2];
        INFO(estimators[e] << ": without the quad (" << o.mean.x << " +- " << o.standard_error.x
                           << "), facing away (" << a.mean.x << " +- " << a.standard_error.x
                           << "), facing the floor (" << f.mean.x << " +- " << f.standard_error.x
                           << "), mis facing away (" << ref.mean.x << " +- " << ref.standard_error.x
                           << ")");
        CHECK(a.nan_samples == 0);
        for (int c = 0; c < 3; ++c) {
            // The strategies agree with each other (mis the reference) and with the open scene.
            CHECK(std::abs(a.mean[c] - ref.mean[c]) <=
                  4.5 * std::hypot(a.standard_error[c], ref.standard_error[c]));
            CHECK(std::abs(a.mean[c] - o.mean[c]) <=
                  4.5 * std::hypot(a.standard_error[c], o.standard_error[c]));
            CHECK(a.standard_error[c] < 0.05 * a.mean[c]);  // not vacuous
            // Facing the floor the quad is there: it shadows most of what the camera sees.
            CHECK(f.mean[c] < 0.5 * o.mean[c]);
        }
    }
}

TEST_CASE("a single-sided glass sphere is hit from inside: transmissive surfaces are never culled",
          "[single-sided][glass]") {
    DeviceContext device = first_device();
    SECTION("a camera inside a closed sphere sees it, unless it is opaque and single-sided") {
        // Ambient occlusion under a sky of 1: a camera ray that leaves the scene sees exactly 1;
        // one that hits the inside of the closed sphere sees 0, its every ambient ray blocked
        // (shadow rays stop at glass).
        RenderSettings settings = image_settings(8, 8, 4);
        settings.estimator = "ambient-cosine";
        settings.sky = glm::vec3(1.0f);
        const Camera camera = looking_down(glm::vec3(0.0f), glm::radians(60.0f));
        for (int kind = 0; kind < 3; ++kind) {  // glass, opaque single-sided, opaque double-sided
            Scene s;
            if (kind == 0)
                s.materials.push_back(glass());
            else
                add_material(s, glm::vec3(0.5f), glm::vec3(0.0f), kind == 2);
            add_sphere(s, glm::vec3(0.0f), 1.0f, 24, 12, 0);
            const GpuSceneData data = gpu_scene_for(s, camera, settings);
            CHECK(data.transmission == (kind == 0));
            const std::vector<float> image = pixels(device, data, settings);
            INFO("kind " << kind << ": first pixel " << image[0]);
            CHECK(all_equal(image, glm::vec3(kind == 1 ? 1.0f : 0.0f)));
        }
    }
    SECTION(
        "refraction through a glass sphere on a culled floor renders the same bits as without "
        "culling") {
        // The floor is seen from its front only, so a single-sided floor (culling built in, the
        // glass not flagged) and a double-sided one (no culling code) must give the same image,
        // paths through the sphere's inside included.
        RenderSettings settings = image_settings(12, 12, 32);
        settings.max_depth = 8;
        settings.estimator = "mis";
        const Camera camera = looking_down(glm::vec3(0.1f, 3.0f, 0.0f), glm::radians(40.0f));
        std::vector<std::vector<float>> images;
        for (bool floor_double_sided : {false, true}) {
            Scene s;
            s.materials.push_back(glass());
            const uint32_t floor =
                add_material(s, glm::vec3(0.6f, 0.5f, 0.4f), glm::vec3(0.0f), floor_double_sided);
            const uint32_t light =
                add_material(s, glm::vec3(0.0f), glm::vec3(6.0f, 6.0f, 5.0f), true);
            add_sphere(s, glm::vec3(0.0f, 0.5f, 0.0f), 0.5f, 32, 16, 0);
            add_level_quad(s, 0.0f, 4.0f, true, floor);
            add_level_quad(s, 2.0f, 0.4f, false, light);
            const GpuSceneData data = gpu_scene_for(s, camera, settings);
            REQUIRE(culls(data) == !floor_double_sided);
            images.push_back(pixels(device, data, settings));
        }
        CHECK(images[0] == images[1]);
    }
}
