// glTF import (host/scene/gltf_import.cpp) and the scene queries (host/scene/scene.cpp):
// the Khronos samples, the project's test scenes, hand-made broken files (tests/data, written by
// scripts/scenes/make_test_gltf.py) and files from tinygltf's own robustness set.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <regex>
#include <string>
#include <vector>

#include "common/error.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"
#include "test_support.h"

using mcrt::test::extended_scene;
using mcrt::test::scene_path;

namespace {

std::string test_data(const std::string& name) { return std::string(MCRT_TEST_DATA) + "/" + name; }

// Loads a file, collecting its warnings.
struct Loaded {
    mcrt::Scene scene;
    std::vector<std::string> warnings;
};

Loaded load(const std::string& path) {
    Loaded loaded;
    loaded.scene =
        mcrt::load_gltf(path, [&](const std::string& w) { loaded.warnings.push_back(w); });
    return loaded;
}

// The message of the InputError that loading `path` throws ("" when it loads).
std::string load_error(const std::string& path) {
    try {
        mcrt::load_gltf(path, nullptr);
    } catch (const mcrt::InputError& e) {
        return e.what();
    }
    return "";
}

size_t count_containing(const std::vector<std::string>& texts, const std::string& part) {
    return static_cast<size_t>(std::count_if(texts.begin(), texts.end(), [&](const std::string& t) {
        return t.find(part) != std::string::npos;
    }));
}

glm::vec3 vertex(const mcrt::Scene& scene, size_t triangle, int corner) {
    return scene.positions[3 * triangle + static_cast<size_t>(corner)];
}

// Geometric normal of the front face: cross(p1 − p0, p2 − p0), normalized.
glm::vec3 front_normal(const mcrt::Scene& scene, size_t triangle) {
    return glm::normalize(glm::cross(vertex(scene, triangle, 1) - vertex(scene, triangle, 0),
                                     vertex(scene, triangle, 2) - vertex(scene, triangle, 0)));
}

glm::vec3 centroid(const mcrt::Scene& scene, size_t triangle) {
    return (vertex(scene, triangle, 0) + vertex(scene, triangle, 1) + vertex(scene, triangle, 2)) /
           3.0f;
}

bool near(const glm::vec3& a, const glm::vec3& b, float tolerance = 1e-5f) {
    return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::vec3(tolerance)));
}

bool has_vertex(const mcrt::Scene& scene, const glm::vec3& p) {
    return std::any_of(scene.positions.begin(), scene.positions.end(),
                       [&](const glm::vec3& q) { return near(p, q); });
}

std::string file_name(const std::string& path) {
    return std::filesystem::path(path).filename().string();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Khronos sample models
// ---------------------------------------------------------------------------------------------

TEST_CASE("Box: parent and child node matrices transform the 12 triangles", "[gltf][khronos]") {
    const Loaded box = load(scene_path("khronos/Box/Box.gltf"));
    const mcrt::Scene& scene = box.scene;
    CHECK(box.warnings.empty());
    REQUIRE(scene.triangle_count() == 12);
    REQUIRE(scene.positions.size() == 36);
    CHECK(near(scene.bounds_min(), glm::vec3(-0.5f)));
    CHECK(near(scene.bounds_max(), glm::vec3(0.5f)));
    // The root's matrix maps (x, y, z) to (x, z, −y); the first triangle (indices 0, 1, 2) is
    // local (−.5,−.5,.5), (.5,−.5,.5), (−.5,.5,.5) with normal +Z, so +Y in the world.
    CHECK(near(vertex(scene, 0, 0), {-0.5f, 0.5f, 0.5f}));
    CHECK(near(vertex(scene, 0, 1), {0.5f, 0.5f, 0.5f}));
    CHECK(near(vertex(scene, 0, 2), {-0.5f, 0.5f, -0.5f}));
    CHECK(near(front_normal(scene, 0), {0.0f, 1.0f, 0.0f}));
    REQUIRE(scene.materials.size() == 1);
    CHECK(near(scene.materials[0].albedo, {0.8f, 0.0f, 0.0f}));
    CHECK(scene.materials[0].emission == glm::vec3(0.0f));
    CHECK(scene.cameras.empty());
    CHECK(mcrt::collect_emitters(scene).empty());
}

TEST_CASE("Triangle: no scene property and no material", "[gltf][khronos]") {
    const mcrt::Scene scene = load(scene_path("khronos/Triangle/Triangle.gltf")).scene;
    REQUIRE(scene.triangle_count() == 1);
    CHECK(near(vertex(scene, 0, 0), {0, 0, 0}));
    CHECK(near(vertex(scene, 0, 1), {1, 0, 0}));
    CHECK(near(vertex(scene, 0, 2), {0, 1, 0}));
    // The default material: white, not emissive, single-sided.
    REQUIRE(scene.materials.size() == 1);
    CHECK(scene.triangle_material[0] == 0);
    CHECK(scene.materials[0].albedo == glm::vec3(1.0f));
    CHECK(scene.materials[0].emission == glm::vec3(0.0f));
    CHECK_FALSE(scene.materials[0].double_sided);
}

TEST_CASE("TriangleWithoutIndices: a non-indexed primitive", "[gltf][khronos]") {
    const mcrt::Scene scene =
        load(scene_path("khronos/TriangleWithoutIndices/TriangleWithoutIndices.gltf")).scene;
    REQUIRE(scene.triangle_count() == 1);
    CHECK(near(vertex(scene, 0, 0), {0, 0, 0}));
    CHECK(near(vertex(scene, 0, 1), {1, 0, 0}));
    CHECK(near(vertex(scene, 0, 2), {0, 1, 0}));
}

TEST_CASE("SimpleSparseAccessor: bounds reflect the sparse override", "[gltf][khronos]") {
    const mcrt::Scene scene =
        load(scene_path("khronos/SimpleSparseAccessor/SimpleSparseAccessor.gltf")).scene;
    REQUIRE(scene.triangle_count() == 12);
    // The base data lies in y ∈ [0, 1]; the sparse values move vertices 8, 10, 12 up to y = 4.
    CHECK(near(scene.bounds_min(), {0, 0, 0}));
    CHECK(near(scene.bounds_max(), {6, 4, 0}));
    CHECK(has_vertex(scene, {1, 2, 0}));
    CHECK(has_vertex(scene, {3, 3, 0}));
    CHECK(has_vertex(scene, {5, 4, 0}));
}

TEST_CASE("MultipleScenes: only the default scene is imported", "[gltf][khronos]") {
    const mcrt::Scene scene = load(scene_path("khronos/MultipleScenes/MultipleScenes.gltf")).scene;
    // `scene` is 1: its mesh is the unit square (2 triangles); scene 0's single triangle is not
    // imported. Only the square has the corner (1, 1, 0).
    CHECK(scene.triangle_count() == 2);
    CHECK(has_vertex(scene, {1, 1, 0}));
}

TEST_CASE("Cameras: the perspective camera is kept, the orthographic one warned about",
          "[gltf][khronos]") {
    const Loaded loaded = load(scene_path("khronos/Cameras/Cameras.gltf"));
    const mcrt::Scene& scene = loaded.scene;
    CHECK(scene.triangle_count() == 2);
    REQUIRE(scene.cameras.size() == 1);
    CHECK(scene.cameras[0].yfov == Approx(0.7f));
    CHECK(near(glm::vec3(scene.cameras[0].camera_to_world[3]), {0.5f, 0.5f, 3.0f}));
    CHECK(near(glm::vec3(scene.cameras[0].camera_to_world[2]), {0, 0, 1}));
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(count_containing(loaded.warnings, "orthographic") == 1);
}

// ---------------------------------------------------------------------------------------------
// The project's test scenes
// ---------------------------------------------------------------------------------------------

TEST_CASE("McGuire Cornell box: 36 triangles, one camera, a light facing down", "[gltf][cornell]") {
    const mcrt::Scene scene = load(scene_path("cornell/CornellBox-Original.gltf")).scene;
    CHECK(scene.triangle_count() == 36);
    REQUIRE(scene.cameras.size() == 1);
    CHECK(scene.cameras[0].yfov == Approx(glm::radians(39.3f)).epsilon(0.01));
    // Looking down −Z from z ≈ 3.9.
    CHECK(near(glm::vec3(scene.cameras[0].camera_to_world[2]), {0, 0, 1}, 1e-4f));
    CHECK(scene.cameras[0].camera_to_world[3].z == Approx(3.9f).epsilon(0.01));

    const std::vector<mcrt::EmissiveTriangle> emitters = mcrt::collect_emitters(scene);
    REQUIRE(emitters.size() == 2);
    for (const mcrt::EmissiveTriangle& e : emitters) {
        const mcrt::Material& light = scene.materials[scene.triangle_material[e.triangle]];
        // MTL Ke 17 12 4 = [1, 12/17, 4/17] (≈ [1, 0.706, 0.235]) × emissiveStrength 17.
        CHECK(light.emission.r == Approx(17.0f).epsilon(1e-5));
        CHECK(light.emission.g == Approx(12.0f).epsilon(1e-5));
        CHECK(light.emission.b == Approx(4.0f).epsilon(1e-5));
        CHECK_FALSE(light.double_sided);
        // Single-sided, so the front face must be the one facing into the box: down.
        CHECK(near(front_normal(scene, e.triangle), {0, -1, 0}, 1e-4f));
        CHECK(e.power == Approx(mcrt::luminance(light.emission) * e.area * glm::pi<float>()));
    }
}

TEST_CASE("nvpro Cornell box: an instanced mesh and a double-sided box light", "[gltf][cornell]") {
    const Loaded loaded = load(scene_path("cornell-nvpro/cornellBox.gltf"));
    const mcrt::Scene& scene = loaded.scene;
    // 16,720 unique triangles; one 12-triangle mesh is used by two nodes.
    CHECK(scene.triangle_count() == 16732);
    REQUIRE(scene.cameras.size() == 1);
    CHECK(scene.cameras[0].yfov == Approx(0.7175f).epsilon(1e-3));
    const std::vector<mcrt::EmissiveTriangle> emitters = mcrt::collect_emitters(scene);
    REQUIRE(emitters.size() == 12);
    for (const mcrt::EmissiveTriangle& e : emitters) {
        const mcrt::Material& light = scene.materials[scene.triangle_material[e.triangle]];
        CHECK(light.double_sided);
        CHECK(light.emission == glm::vec3(10.0f));
        CHECK(e.power == Approx(2.0f * 10.0f * e.area * glm::pi<float>()));
    }
    // The glass sphere's alphaMode BLEND is read, not warned about.
    CHECK(count_containing(loaded.warnings, "alphaMode") == 0);
    CHECK(std::any_of(scene.materials.begin(), scene.materials.end(), [](const mcrt::Material& m) {
        return m.alpha_mode == mcrt::AlphaMode::Blend;
    }));
}

TEST_CASE("Modern Hall: mirrored emitters keep the front face Mitsuba emits from",
          "[gltf][lights]") {
    const Loaded loaded = load(scene_path("modern-hall/modern-hall.gltf"));
    const mcrt::Scene& scene = loaded.scene;
    CHECK(scene.triangle_count() == 31247);
    CHECK(scene.cameras.size() == 1);
    // 13 emitting shapes: 5 disks of 64 triangles and 8 rectangles of 2; 6 of them sit under a
    // node matrix with a negative determinant.
    const std::vector<mcrt::EmissiveTriangle> emitters = mcrt::collect_emitters(scene);
    CHECK(emitters.size() == 5 * 64 + 8 * 2);
    // Every light is single-sided and lights the hall: its front faces the bounds' centre.
    const glm::vec3 c = 0.5f * (scene.bounds_min() + scene.bounds_max());
    size_t facing_inward = 0;
    for (const mcrt::EmissiveTriangle& e : emitters) {
        CHECK_FALSE(scene.materials[scene.triangle_material[e.triangle]].double_sided);
        if (glm::dot(front_normal(scene, e.triangle), c - centroid(scene, e.triangle)) > 0.0f) {
            ++facing_inward;
        }
    }
    CHECK(facing_inward == emitters.size());
    // Its balustrade is thin-walled glass (KHR_materials_transmission), read without a warning.
    CHECK(count_containing(loaded.warnings, "KHR_materials_transmission") == 0);
    size_t glass = 0;
    for (const mcrt::Material& m : scene.materials) glass += m.transmission == 1.0f ? 1 : 0;
    CHECK(glass == 1);
}

TEST_CASE("GLB files load: the fazil47 Cornell box", "[gltf][glb]") {
    const mcrt::Scene box = load(scene_path("cornell-fazil47/cornell-box.glb")).scene;
    CHECK(box.triangle_count() == 1040);
    CHECK(box.cameras.empty());
    CHECK_FALSE(mcrt::collect_emitters(box).empty());
}

TEST_CASE("GLB files load: the Stanford bunny", "[gltf][glb][extended]") {
    const mcrt::Scene bunny = load(extended_scene("stanford/bunny_zipper.glb")).scene;
    CHECK(bunny.triangle_count() == 69451);
    CHECK(bunny.cameras.empty());
    CHECK(mcrt::collect_emitters(bunny).empty());
    const glm::vec3 extent = bunny.bounds_max() - bunny.bounds_min();
    CHECK(extent.x > 0.1f);
    CHECK(extent.x < 0.2f);
}

TEST_CASE("tinygltf robustness files either load or throw InputError", "[gltf][robustness]") {
    const std::vector<std::string> files = {
        "robustness/tinygltf/BoundsChecking/integer-out-of-bounds.gltf",
        "robustness/tinygltf/BoundsChecking/invalid-buffer-index.gltf",
        "robustness/tinygltf/BoundsChecking/invalid-buffer-view-index.gltf",
        "robustness/tinygltf/BoundsChecking/invalid-primitive-indices.gltf",
        "robustness/tinygltf/regression/zero-sized-bin-chunk-issue-440.glb",
        "robustness/tinygltf/box01.glb",
    };
    for (const std::string& file : files) {
        INFO(file);
        const std::string path = scene_path(file);
        try {
            mcrt::load_gltf(path, nullptr);
        } catch (const mcrt::InputError& e) {
            CHECK(std::string(e.what()).find(file_name(path)) != std::string::npos);
        }
    }
    // The four BoundsChecking files are invalid.
    for (size_t i = 0; i < 4; ++i) CHECK_FALSE(load_error(scene_path(files[i])).empty());
    CHECK(load(scene_path("robustness/tinygltf/box01.glb")).scene.triangle_count() == 12);
}

// ---------------------------------------------------------------------------------------------
// Hand-made files (tests/data, scripts/scenes/make_test_gltf.py)
// ---------------------------------------------------------------------------------------------

TEST_CASE("Broken files throw InputError naming the file and the element", "[gltf][invalid]") {
    struct Broken {
        const char* file;
        const char* element;  // part of the message
    };
    const Broken broken[] = {
        {"index_out_of_range.gltf", "index 5"},
        {"node_cycle.gltf", "node cycle through node 0"},
        {"child_out_of_range.gltf", "node 0: child 7 out of range"},
        {"accessor_overrun.gltf", "accessor 0"},
        {"buffer_view_overrun.gltf", "bufferView 0"},
        {"nan_position.gltf", "not finite"},
        {"huge_position.gltf", "1e30"},
        {"negative_emissive_strength.gltf", "emissiveStrength"},
        {"camera_yfov_zero.gltf", "camera 0: yfov"},
        {"mesh_out_of_range.gltf", "node 0: mesh 3 out of range"},
        {"material_out_of_range.gltf", "material 2 out of range"},
        {"scene_out_of_range.gltf", "scene 4 out of range"},
        {"rootless_cycle.gltf", "node cycle"},
        // Found by fuzzing: Le × area overflowed the float power of light selection.
        {"emitter_power_overflow.gltf", "mesh 0 primitive 0: triangle 0: emitted power"},
    };
    for (const Broken& b : broken) {
        INFO(b.file);
        const std::string path = test_data(b.file);
        REQUIRE(std::filesystem::exists(path));
        REQUIRE_THROWS_AS(mcrt::load_gltf(path, nullptr), mcrt::InputError);
        const std::string message = load_error(path);
        INFO(message);
        CHECK(message.find(b.file) != std::string::npos);
        CHECK(message.find(b.element) != std::string::npos);
    }
}

TEST_CASE("Missing and garbage files throw InputError naming the file", "[gltf][invalid]") {
    const std::string missing = test_data("no_such_file.gltf");
    REQUIRE_THROWS_AS(mcrt::load_gltf(missing, nullptr), mcrt::InputError);
    CHECK(load_error(missing).find("no_such_file.gltf") != std::string::npos);

    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mcrt_gltf_garbage";
    std::filesystem::create_directories(dir);
    const std::vector<std::pair<std::string, std::string>> garbage = {
        {"truncated.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": ["},
        {"not_json.gltf", "solid cube\nfacet normal 0 0 1\n"},
        {"truncated.glb", std::string("glTF\x02\0\0\0\x40\0\0\0", 12)},
        {"empty.glb", ""},
    };
    for (const auto& [name, bytes] : garbage) {
        INFO(name);
        const std::string path = (dir / name).string();
        std::ofstream(path, std::ios::binary) << bytes;
        REQUIRE_THROWS_AS(mcrt::load_gltf(path, nullptr), mcrt::InputError);
        CHECK(load_error(path).find(name) != std::string::npos);
    }
    std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Loading from memory (the fuzz target's entry point, tests/fuzz) and the fuzz corpus
// ---------------------------------------------------------------------------------------------

std::vector<unsigned char> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)),
                                      std::istreambuf_iterator<char>());
}

TEST_CASE("load_gltf_from_memory imports what load_gltf imports", "[gltf][memory]") {
    for (const char* name : {"trs_transform.gltf", "shared_subtree.gltf"}) {
        INFO(name);
        const mcrt::Scene from_file = mcrt::load_gltf(test_data(name), nullptr);
        const mcrt::Scene from_memory =
            mcrt::load_gltf_from_memory(name, file_bytes(test_data(name)), nullptr);
        CHECK(from_memory.path == name);
        CHECK(from_memory.positions == from_file.positions);
        CHECK(from_memory.triangle_material == from_file.triangle_material);
        CHECK(from_memory.materials.size() == from_file.materials.size());
    }
    const std::string glb = scene_path("robustness/tinygltf/box01.glb");
    CHECK(mcrt::load_gltf_from_memory("box01.glb", file_bytes(glb), nullptr).triangle_count() ==
          12);
    // Broken files fail the same way, named by the name given.
    try {
        mcrt::load_gltf_from_memory("cycle", file_bytes(test_data("node_cycle.gltf")), nullptr);
        FAIL("node_cycle.gltf loaded from memory");
    } catch (const mcrt::InputError& e) {
        CHECK(std::string(e.what()).find("cycle: node cycle through node 0") == 0);
    }
}

TEST_CASE("load_gltf_from_memory reads nothing from disk", "[gltf][memory]") {
    // A buffer naming a file that exists next to the working directory is still refused.
    const std::string text = R"({"asset": {"version": "2.0"}, "buffers": [{"uri": ")" +
                             test_data("trs_transform.gltf") + R"(", "byteLength": 4}]})";
    const std::vector<unsigned char> bytes(text.begin(), text.end());
    REQUIRE_THROWS_AS(mcrt::load_gltf_from_memory("external.gltf", bytes, nullptr),
                      mcrt::InputError);
    REQUIRE_THROWS_AS(mcrt::load_gltf_from_memory("empty.gltf", {}, nullptr), mcrt::InputError);
    const std::vector<unsigned char> truncated_glb = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 64, 0};
    REQUIRE_THROWS_AS(mcrt::load_gltf_from_memory("truncated.glb", truncated_glb, nullptr),
                      mcrt::InputError);
}

// The fuzzer's seed corpus, with every input that ever crashed it: each loads or is refused.
TEST_CASE("Every file of the fuzz corpus loads or throws InputError", "[gltf][robustness][fuzz]") {
    const std::filesystem::path corpus = std::filesystem::path(MCRT_TEST_DATA) / "../fuzz/corpus";
    REQUIRE(std::filesystem::is_directory(corpus));
    size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
        INFO(entry.path().filename().string());
        ++files;
        try {
            mcrt::load_gltf_from_memory(entry.path().filename().string(),
                                        file_bytes(entry.path().string()), nullptr);
        } catch (const mcrt::InputError&) {
        }
    }
    CHECK(files >= 30);
}

// Every integer of Box.gltf's JSON replaced, one at a time, by out-of-range or negative values:
// each variant loads or throws InputError, never anything else.
TEST_CASE("Box.gltf with corrupted indices and counts never crashes", "[gltf][robustness]") {
    std::ifstream in(scene_path("khronos/Box/Box.gltf"));
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::regex integer(R"((":\s*\[?\s*)(\d+)([,\s\]}]))");
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mcrt_gltf_mutants";
    std::filesystem::create_directories(dir);
    size_t variants = 0, rejected = 0;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), integer);
         it != std::sregex_iterator(); ++it) {
        for (const char* replacement : {"-1", "7", "100000", "4294967295"}) {
            std::string mutant = text;
            mutant.replace(static_cast<size_t>(it->position(2)), static_cast<size_t>(it->length(2)),
                           replacement);
            const std::string path =
                (dir / ("mutant" + std::to_string(variants++) + ".gltf")).string();
            std::ofstream(path) << mutant;
            try {
                mcrt::load_gltf(path, nullptr);
            } catch (const mcrt::InputError& e) {
                ++rejected;
                CHECK(std::string(e.what()).find(file_name(path)) != std::string::npos);
            }
        }
    }
    std::filesystem::remove_all(dir);
    CHECK(variants > 40);
    CHECK(rejected > 0);
}

TEST_CASE("An empty scene loads with no triangles", "[gltf]") {
    const Loaded loaded = load(test_data("empty_scene.gltf"));
    CHECK(loaded.scene.triangle_count() == 0);
    CHECK(loaded.scene.positions.empty());
    CHECK(loaded.scene.cameras.empty());
    CHECK(loaded.warnings.empty());
    CHECK(mcrt::collect_emitters(loaded.scene).empty());
}

TEST_CASE("A file without scenes renders its root nodes", "[gltf]") {
    const mcrt::Scene scene = load(test_data("no_scenes.gltf")).scene;
    REQUIRE(scene.triangle_count() == 2);
    CHECK(near(scene.bounds_min(), {0, 0, 0}));
    CHECK(near(scene.bounds_max(), {1, 1, 5}));
}

TEST_CASE("A mirroring node keeps the emitter's front face (negative determinant)", "[gltf]") {
    for (const char* file : {"mirrored_emitter.gltf", "mirrored_matrix_emitter.gltf"}) {
        INFO(file);
        const mcrt::Scene scene = load(test_data(file)).scene;
        REQUIRE(scene.triangle_count() == 1);
        // Local (0,0,0), (1,0,0), (0,1,0) faces +Z; x ↦ −x puts the triangle at x ≤ 0 and, without
        // the winding fix, would turn its front face to −Z.
        CHECK(scene.bounds_min().x == Approx(-1.0f));
        CHECK(scene.bounds_max().x == Approx(0.0f));
        CHECK(near(front_normal(scene, 0), {0, 0, 1}));
        REQUIRE(mcrt::collect_emitters(scene).size() == 1);
    }
}

TEST_CASE("TRS transforms compose as T·R·S", "[gltf]") {
    const mcrt::Scene scene = load(test_data("trs_transform.gltf")).scene;
    REQUIRE(scene.triangle_count() == 1);
    // Scale (2,3,4), then 90° about +Z ((x, y) ↦ (−y, x)), then translate (1,2,3).
    CHECK(near(vertex(scene, 0, 0), {1, 4, 3}));
    CHECK(near(vertex(scene, 0, 1), {-2, 2, 3}));
    CHECK(near(vertex(scene, 0, 2), {1, 2, 7}));
}

TEST_CASE("Textures fill their slots beside the factors; a shared image is decoded once",
          "[gltf][textures]") {
    const Loaded loaded = load(test_data("texture_reference.gltf"));
    CHECK(loaded.warnings.empty());
    const mcrt::Scene& scene = loaded.scene;
    REQUIRE(scene.materials.size() == 2);
    CHECK(near(scene.materials[0].albedo, {0.5f, 0.25f, 0.125f}));
    CHECK(scene.materials[0].base_color_texture.image == 0);
    CHECK(scene.materials[0].base_color_texture.srgb);
    CHECK(near(scene.materials[1].emission, glm::vec3(4.0f)));
    CHECK(scene.materials[1].normal_texture.image == 0);
    CHECK_FALSE(scene.materials[1].normal_texture.srgb);
    REQUIRE(scene.images.size() == 1);
    CHECK(scene.images[0].width == 1);
    CHECK(scene.images[0].rgba == std::vector<uint8_t>{255, 128, 0, 255});
    CHECK(mcrt::collect_emitters(scene).size() == 1);
}

TEST_CASE("A node shared by two parents is instanced, not a cycle", "[gltf]") {
    const mcrt::Scene scene = load(test_data("shared_subtree.gltf")).scene;
    REQUIRE(scene.triangle_count() == 2);
    CHECK(near(vertex(scene, 0, 0), {10, 0, 0}));
    CHECK(near(vertex(scene, 1, 0), {0, 10, 0}));
}

TEST_CASE("A sparse accessor without a bufferView starts from zeros", "[gltf]") {
    const mcrt::Scene scene = load(test_data("sparse_without_buffer_view.gltf")).scene;
    REQUIRE(scene.triangle_count() == 1);
    CHECK(near(vertex(scene, 0, 0), {0, 0, 0}));
    CHECK(near(vertex(scene, 0, 1), {2, 0, 0}));
    CHECK(near(vertex(scene, 0, 2), {0, 3, 0}));
}

TEST_CASE("Strips and fans become front-facing triangles; lines are skipped", "[gltf]") {
    const Loaded loaded = load(test_data("strips_fans_lines.gltf"));
    REQUIRE(loaded.scene.triangle_count() == 4);
    for (size_t t = 0; t < 4; ++t) CHECK(near(front_normal(loaded.scene, t), {0, 0, 1}));
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(count_containing(loaded.warnings, "lines") == 1);
}

TEST_CASE("Positions interleaved with normals respect byteStride", "[gltf]") {
    const mcrt::Scene scene = load(test_data("interleaved_positions.gltf")).scene;
    REQUIRE(scene.triangle_count() == 1);
    CHECK(near(vertex(scene, 0, 0), {0, 0, 0}));
    CHECK(near(vertex(scene, 0, 1), {1, 0, 0}));
    CHECK(near(vertex(scene, 0, 2), {0, 1, 0}));
}

// ---------------------------------------------------------------------------------------------
// Scene queries
// ---------------------------------------------------------------------------------------------

namespace {

// Triangles: 0 emissive single-sided (area 0.5), 1 emissive double-sided (area 2), 2 emissive but
// degenerate (collinear), 3 not emissive, 4 emissive with zero luminance (black).
mcrt::Scene emitter_test_scene() {
    mcrt::Scene scene;
    auto material = [](const char* name, glm::vec3 Le, bool double_sided) {
        mcrt::Material m;
        m.name = name;
        m.albedo = glm::vec3(0.5f);
        m.emission = Le;
        m.double_sided = double_sided;
        return m;
    };
    scene.materials = {material("warm", glm::vec3(4.0f, 2.0f, 1.0f), false),
                       material("both", glm::vec3(1.0f), true),
                       material("grey", glm::vec3(0.0f), false)};
    auto add = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material) {
        scene.positions.insert(scene.positions.end(), {a, b, c});
        scene.triangle_material.push_back(material);
    };
    add({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    add({0, 0, 0}, {2, 0, 0}, {0, 0, 2}, 1);
    add({0, 0, 0}, {1, 1, 1}, {2, 2, 2}, 0);
    add({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 2);
    add({0, 0, 0}, {5, 0, 0}, {0, 5, 0}, 2);
    return scene;
}

}  // namespace

TEST_CASE("collect_emitters: areas and powers; degenerate and black triangles dropped", "[scene]") {
    const mcrt::Scene scene = emitter_test_scene();
    const std::vector<mcrt::EmissiveTriangle> emitters = mcrt::collect_emitters(scene);
    REQUIRE(emitters.size() == 2);
    CHECK(emitters[0].triangle == 0);
    CHECK(emitters[0].area == Approx(0.5f));
    const float warm = 0.2126f * 4.0f + 0.7152f * 2.0f + 0.0722f * 1.0f;
    CHECK(mcrt::luminance({4.0f, 2.0f, 1.0f}) == Approx(warm));
    CHECK(emitters[0].power == Approx(warm * 0.5f * glm::pi<float>()));
    CHECK(emitters[1].triangle == 1);
    CHECK(emitters[1].area == Approx(2.0f));
    CHECK(emitters[1].power == Approx(1.0f * 2.0f * glm::pi<float>() * 2.0f));
}

TEST_CASE("collect_emitters drops triangles with non-finite vertices", "[scene]") {
    mcrt::Scene scene = emitter_test_scene();
    scene.positions[1].x = std::numeric_limits<float>::infinity();
    const std::vector<mcrt::EmissiveTriangle> emitters = mcrt::collect_emitters(scene);
    REQUIRE(emitters.size() == 1);
    CHECK(emitters[0].triangle == 1);
}

TEST_CASE("Scene bounds; an empty scene has the empty box at the origin", "[scene]") {
    const mcrt::Scene scene = emitter_test_scene();
    CHECK(scene.bounds_min() == glm::vec3(0.0f));
    CHECK(scene.bounds_max() == glm::vec3(5.0f, 5.0f, 2.0f));
    const mcrt::Scene empty;
    CHECK(empty.bounds_min() == glm::vec3(0.0f));
    CHECK(empty.bounds_max() == glm::vec3(0.0f));
}

namespace {

// camera_to_world is a right-handed rigid frame: orthonormal columns, right × up = back.
void check_rigid_frame(const glm::mat4& m) {
    const glm::vec3 right(m[0]), up(m[1]), back(m[2]);
    CHECK(glm::length(right) == Approx(1.0f));
    CHECK(glm::length(up) == Approx(1.0f));
    CHECK(glm::length(back) == Approx(1.0f));
    CHECK(glm::dot(right, up) == Approx(0.0f).margin(1e-6));
    CHECK(glm::dot(up, back) == Approx(0.0f).margin(1e-6));
    CHECK(near(glm::cross(right, up), back));
    CHECK(m[3].w == 1.0f);
    CHECK(m[0].w == 0.0f);
    CHECK(m[1].w == 0.0f);
    CHECK(m[2].w == 0.0f);
}

}  // namespace

TEST_CASE("bench_camera follows the benchmark contract", "[scene]") {
    mcrt::Scene scene;
    scene.positions = {{-1, 0, 2}, {3, 2, 2}, {1, 4, 6}};
    scene.triangle_material = {0};
    scene.materials = {mcrt::Material{}};
    const mcrt::Camera camera = mcrt::bench_camera(scene);
    const glm::vec3 c(1, 2, 4);
    const float diag = glm::length(glm::vec3(4, 4, 4));
    const glm::vec3 eye = c + diag * glm::vec3(0.35f, 0.30f, 0.55f);
    const glm::mat4& m = camera.camera_to_world;
    CHECK(near(glm::vec3(m[3]), eye, 1e-4f));
    // Looks at c (down its −Z), +Y up, 45°.
    CHECK(near(-glm::vec3(m[2]), glm::normalize(c - eye)));
    CHECK(glm::vec3(m[1]).y > 0.0f);
    CHECK(glm::vec3(m[0]).y == Approx(0.0f).margin(1e-6));
    CHECK(camera.yfov == Approx(glm::radians(45.0f)));
    check_rigid_frame(m);
}

TEST_CASE("bench_camera of an empty or point-like scene is still a valid frame", "[scene]") {
    mcrt::Scene point;
    point.positions = {{2, 2, 2}, {2, 2, 2}, {2, 2, 2}};
    point.triangle_material = {0};
    point.materials = {mcrt::Material{}};
    for (const mcrt::Scene& scene : {mcrt::Scene{}, point}) {
        const mcrt::Camera camera = mcrt::bench_camera(scene);
        const glm::mat4& m = camera.camera_to_world;
        for (int col = 0; col < 4; ++col) {
            for (int row = 0; row < 4; ++row) CHECK(std::isfinite(m[col][row]));
        }
        check_rigid_frame(m);
        // It looks at the (degenerate) box's centre.
        const glm::vec3 c = scene.bounds_min();
        CHECK(near(-glm::vec3(m[2]), glm::normalize(c - glm::vec3(m[3]))));
    }
}

TEST_CASE("Cameras of the test scenes are right-handed rigid frames", "[gltf][scene]") {
    for (const char* file : {"khronos/Cameras/Cameras.gltf", "modern-hall/modern-hall.gltf",
                             "cornell-nvpro/cornellBox.gltf"}) {
        INFO(file);
        const mcrt::Scene scene = load(scene_path(file)).scene;
        REQUIRE_FALSE(scene.cameras.empty());
        for (const mcrt::Camera& camera : scene.cameras) check_rigid_frame(camera.camera_to_world);
    }
}
