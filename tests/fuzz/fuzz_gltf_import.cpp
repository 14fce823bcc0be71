// libFuzzer target: the bytes of a .gltf or .glb file through mcrt's glTF import, as
// `mcrt render` loads a scene, then through the host's BVH build and light distributions. Refusing
// a file (InputError) is the expected outcome for most inputs; anything else escaping is a crash,
// and so is an imported scene that breaks the contract the renderer relies on (finite positions,
// in-range materials, finite emission, rigid cameras with yfov in (0, pi)), which the checks below
// turn into an abort.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bvh/bvh.h"
#include "common/error.h"
#include "lights/discrete.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"

namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void require(bool condition, const char* what) {
    if (condition) return;
    std::fprintf(stderr, "fuzz_gltf_import: imported scene breaks the contract: %s\n", what);
    std::abort();
}

// The corners' texture attributes (scene.h): none, or one of each per corner, finite; each frame
// zero (no normal texture) or a unit normal and a unit tangent with w = ±1.
void check_corner_attributes(const mcrt::Scene& scene) {
    if (!scene.textured()) {
        require(scene.normals.empty() && scene.tangents.empty(), "no frames without texcoords");
        return;
    }
    const size_t corners = scene.positions.size();
    require(scene.texcoords.size() == corners && scene.normals.size() == corners &&
                scene.tangents.size() == corners,
            "corner attributes parallel to positions");
    auto unit = [](const glm::vec3& v) { return std::abs(glm::length(v) - 1.0f) < 1e-3f; };
    for (size_t c = 0; c < corners; ++c) {
        const glm::vec4& uv = scene.texcoords[c];
        require(finite(glm::vec3(uv)) && std::isfinite(uv.w), "finite texcoords");
        const glm::vec3& n = scene.normals[c];
        const glm::vec4& t = scene.tangents[c];
        if (n == glm::vec3(0.0f)) {
            require(t == glm::vec4(0.0f), "no tangent without a normal");
            continue;
        }
        require(unit(n) && unit(glm::vec3(t)) && std::abs(t.w) == 1.0f, "unit frames, w = ±1");
    }
}

// What the renderer assumes of every scene load_gltf returns.
void check_scene(const mcrt::Scene& scene) {
    require(scene.positions.size() == 3 * scene.triangle_count(), "three corners per triangle");
    for (const glm::vec3& p : scene.positions) require(finite(p), "finite positions");
    for (uint32_t m : scene.triangle_material)
        require(m < scene.materials.size(), "material in range");
    for (const mcrt::Material& m : scene.materials) {
        require(finite(m.albedo) && glm::all(glm::greaterThanEqual(m.albedo, glm::vec3(0.0f))),
                "finite non-negative albedo");
        require(finite(m.emission) && glm::all(glm::greaterThanEqual(m.emission, glm::vec3(0.0f))),
                "finite non-negative emission");
    }
    for (const mcrt::Camera& c : scene.cameras) {
        require(c.yfov > 0.0f && c.yfov < 3.14159275f, "yfov in (0, pi)");
        for (int i = 0; i < 4; ++i)
            require(finite(glm::vec3(c.camera_to_world[i])), "finite camera");
    }
    require(finite(scene.bounds_min()) && finite(scene.bounds_max()), "finite bounds");
    check_corner_attributes(scene);
    for (const mcrt::EmissiveTriangle& e : mcrt::collect_emitters(scene)) {
        require(e.triangle < scene.triangle_count(), "emitter in range");
        require(std::isfinite(e.area) && e.area > 0.0f, "finite positive emitter area");
        require(std::isfinite(e.power) && e.power >= 0.0f, "finite emitter power");
    }
    const mcrt::Camera bench = mcrt::bench_camera(scene);
    for (int i = 0; i < 4; ++i)
        require(finite(glm::vec3(bench.camera_to_world[i])), "finite bench camera");
}

// What the renderer builds from the scene on the host: the BVH with its packets (every triangle
// in exactly one packet lane) and the light CDF (on the 2^-24 grid, every positive power
// reachable) and alias table.
void check_host_structures(const mcrt::Scene& scene) {
    const mcrt::Bvh bvh = mcrt::build_bvh(scene);
    std::vector<int> seen(scene.triangle_count(), 0);
    for (const mcrt::gpu::TrianglePacket& p : bvh.packets)
        for (uint32_t triangle : p.index) {
            if (triangle == 0xffffffffu) continue;
            require(triangle < seen.size(), "packet lane in range");
            if (triangle < seen.size()) ++seen[triangle];
        }
    for (int n : seen) require(n == 1, "every triangle in one packet lane");
    require(bvh.stats.depth4 <= mcrt::kMaxBvh4Depth, "BVH4 depth within the stack bound");

    std::vector<double> powers;
    for (const mcrt::EmissiveTriangle& e : mcrt::collect_emitters(scene)) powers.push_back(e.power);
    const std::vector<float> cdf = mcrt::build_cdf(powers);
    require(cdf.size() == (powers.empty() ? 1 : powers.size() + 1), "CDF size");
    double total = 0;
    for (double p : powers) total += p;
    if (total > 0) {
        require(cdf.back() == 1.0f, "CDF ends at 1");
        for (size_t i = 0; i < powers.size(); ++i)
            require(powers[i] > 0 ? cdf[i + 1] > cdf[i] : cdf[i + 1] == cdf[i],
                    "a CDF step for each light with power, none for the others");
    }
    require(mcrt::build_alias_table(powers).size() == (total > 0 ? powers.size() : 0),
            "alias table size");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // A copy of exactly `size` bytes, so that ASan sees any read past the end.
    const std::vector<unsigned char> bytes(data, data + size);
    try {
        const mcrt::Scene scene =
            mcrt::load_gltf_from_memory("fuzz-input", bytes, [](const std::string&) {});
        check_scene(scene);
        check_host_structures(scene);
    } catch (const mcrt::InputError&) {
        // Refused with a message: what a broken file should get.
    }
    return 0;
}
