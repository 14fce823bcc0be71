// Scenes that hang or crash the loader, values that overflow, silently wrong input
// (docs/ROBUSTNESS.md, "Hostile input"). Each refusal is one InputError (exit 2 from mcrt
// render) naming the cause; what is accepted with a warning warns once. Cases that hung or crashed the old loader
// run through the mcrt executable, so that a regression fails the test instead of hanging it.
#include <sys/stat.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "common/error.h"
#include "image/image_check.h"
#include "process_support.h"
#include "scene/gltf_import.h"

using namespace mcrt;
using namespace mcrt::test;
namespace fs = std::filesystem;

namespace {

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) v |= bytes[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

// Buffer bytes: one triangle of half-size `s` in the xz plane (front face up), then indices.
std::string triangle_buffer_uri(double s, const std::vector<uint16_t>& indices = {0, 1, 2}) {
    const float p[9] = {float(-s), 0, float(s), float(s), 0, float(s), 0, 0, float(-s)};
    std::vector<unsigned char> bytes(sizeof p + 2 * indices.size());
    std::memcpy(bytes.data(), p, sizeof p);
    std::memcpy(bytes.data() + sizeof p, indices.data(), 2 * indices.size());
    return "data:application/octet-stream;base64," + base64(bytes);
}

struct Gltf {
    std::string asset = R"("asset": {"version": "2.0"})";
    std::string material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})";
    std::string nodes = R"([{"mesh": 0}])";
    std::string scene_nodes = "[0]";
    std::string extra;  // more top-level properties, each followed by a comma
    double size = 1.0;
    std::vector<uint16_t> indices = {0, 1, 2};
    std::string buffer_uri;  // default: the triangle as a data uri

    std::string text() const {
        const std::string uri = buffer_uri.empty() ? triangle_buffer_uri(size, indices) : buffer_uri;
        const size_t length = 36 + 2 * indices.size();
        return "{" + asset + "," + extra + R"("scene": 0, "scenes": [{"nodes": )" + scene_nodes +
               R"(}], "nodes": )" + nodes + R"(, "materials": [)" + material +
               R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": )" +
               std::to_string(indices.size()) + R"(, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": )" +
               std::to_string(2 * indices.size()) + R"(}],
  "buffers": [{"byteLength": )" + std::to_string(length) + R"(, "uri": ")" + uri + R"("}]})";
    }
};

struct Loaded {
    Scene scene;
    std::vector<std::string> warnings;
};

Loaded load(const Gltf& g) {
    Loaded result;
    const std::string text = g.text();
    result.scene = load_gltf_from_memory("test.gltf", std::vector<unsigned char>(text.begin(), text.end()),
                                         [&](const std::string& w) { result.warnings.push_back(w); });
    return result;
}

std::string refusal(const Gltf& g) {
    try {
        load(g);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

void write_text(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// `mcrt render` of `scene`: exit 2 with one error line holding `needle`, within the timeout.
void require_render_refused(const std::string& scene, const std::string& needle) {
    TempDir logs("mcrt-hostile-logs");
    const ProcessResult r = run_process(
        MCRT_EXE, {"render", scene, "--width", "8", "--height", "8", "--spp", "16", "--quiet", "--out",
                   logs / "a.exr"}, logs.path(), 30);
    INFO("stderr: " << r.err << " signal " << r.signal);
    REQUIRE_FALSE(r.timed_out);
    CHECK(r.exit_code == 2);
    CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
    CHECK(r.err.find(needle) != std::string::npos);
    CHECK_FALSE(fs::exists(logs / "a.exr"));
}

}  // namespace

TEST_CASE("the helper scene loads", "[gltf][hostile]") {
    const Loaded l = load(Gltf{});
    CHECK(l.scene.triangle_count() == 1);
    CHECK(l.warnings.empty());
}

// ---- class 2: inputs that hang or crash the loader ------------------------------------------

TEST_CASE("JSON nested 20,000 levels deep is refused before tinygltf", "[gltf][hostile]") {
    TempDir dir("mcrt-hostile");
    Gltf g;
    g.extra = R"("extras": )" + std::string(20000, '[') + std::string(20000, ']') + ",";
    write_text(dir / "deep.gltf", g.text());
    require_render_refused(dir / "deep.gltf", "JSON nested deeper than 512 levels");
    // Brackets inside strings do not count.
    Gltf quoted;
    quoted.extra = R"("extras": {"text": ")" + std::string(20000, '[') + R"("},)";
    CHECK(load(quoted).scene.triangle_count() == 1);
}

TEST_CASE("a uri or scene path naming a FIFO, directory or device is refused naming it",
          "[gltf][hostile]") {
    TempDir dir("mcrt-hostile");
    REQUIRE(::mkfifo((dir / "fifo.bin").c_str(), 0600) == 0);
    fs::create_directory(dir / "dir.bin");
    Gltf g;
    g.buffer_uri = "fifo.bin";
    write_text(dir / "fifo.gltf", g.text());
    require_render_refused(dir / "fifo.gltf", "is a FIFO (named pipe); only regular files are read");
    g.buffer_uri = "dir.bin";
    write_text(dir / "dir.gltf", g.text());
    require_render_refused(dir / "dir.gltf", "is a directory; only regular files are read");
    g.buffer_uri = "missing.bin";
    write_text(dir / "missing.gltf", g.text());
    require_render_refused(dir / "missing.gltf", "missing.bin : no such file");
    // An image uri (textures are not used, but tinygltf reads the file) is no exception.
    Gltf image;
    image.extra = R"("images": [{"uri": "fifo.bin"}],)";
    write_text(dir / "image.gltf", image.text());
    require_render_refused(dir / "image.gltf", "is a FIFO (named pipe)");
    // The scene itself.
    require_render_refused(dir / "fifo.bin", "is a FIFO (named pipe)");
    require_render_refused(dir / "dir.bin", "is a directory");
    struct stat st {};
    if (::stat("/dev/zero", &st) == 0 && S_ISCHR(st.st_mode))
        require_render_refused("/dev/zero", "is a character device");
}

TEST_CASE("extensionsRequired naming an unimplemented extension is refused", "[gltf][hostile]") {
    Gltf g;
    g.extra = R"("extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],)";
    CHECK(refusal(g).find("extensionsRequired names KHR_draco_mesh_compression") != std::string::npos);
    g.extra = R"("extensionsUsed": ["KHR_materials_emissive_strength"], "extensionsRequired": ["KHR_materials_emissive_strength"],)";
    CHECK(load(g).scene.triangle_count() == 1);
}

TEST_CASE("a hierarchy expanding to 2^30 node instances is refused before expanding", "[gltf][hostile]") {
    // Node i lists node i + 1 twice: 2^31 − 1 instances from 31 nodes.
    std::string nodes = "[";
    for (int i = 0; i < 31; ++i) {
        nodes += i < 30 ? "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}," : "{\"mesh\": 0}";
    }
    Gltf g;
    g.nodes = nodes + "]";
    const std::string why = refusal(g);
    CHECK(why.find("expands to 2.14748e+09 node instances, more than 16777216") != std::string::npos);
    // Many instances of a big mesh: refused by the triangle bound, before expanding.
    std::string few = "[";
    for (int i = 0; i < 15; ++i) few += i < 14 ? "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}," : "{\"mesh\": 0}";
    Gltf big;
    big.nodes = few + "]";
    big.indices.assign(30000, 0);  // 10,000 (degenerate) triangles × 16,384 instances
    CHECK(refusal(big).find("triangles, more than") != std::string::npos);
}

// ---- class 3: values that overflow ------------------------------------------------------------

TEST_CASE("radiance that cannot be summed in single precision is refused", "[gltf][hostile]") {
    Gltf g;
    g.material = R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e31}}})";
    CHECK(refusal(g).find("emission 1e+31 exceeds 1e+30") != std::string::npos);
    // Each instance's power is a float, their sum is not: 16 instances of 6e37.
    Gltf many;
    many.size = 1e11;
    many.material = R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e15}}})";
    std::string nodes = "[", roots = "[";
    for (int i = 0; i < 16; ++i) {
        nodes += std::string(i ? "," : "") + "{\"mesh\": 0, \"translation\": [0, " + std::to_string(i) + "e10, 0]}";
        roots += std::string(i ? "," : "") + std::to_string(i);
    }
    many.nodes = nodes + "]";
    many.scene_nodes = roots + "]";
    CHECK(refusal(many).find("summed power") != std::string::npos);
}

TEST_CASE("a sky that overflows is refused, and non-finite pixels are counted", "[cli][hostile]") {
    TempDir logs("mcrt-hostile-logs");
    const ProcessResult r = run_process(
        MCRT_EXE, {"render", std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf", "--estimator",
                   "ambient-cosine", "--sky", "1e38", "--width", "8", "--height", "8", "--quiet", "--out",
                   logs / "a.exr"}, logs.path(), 60);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("--sky 1e38") != std::string::npos);
    CHECK_FALSE(fs::exists(logs / "a.exr"));
    Image img(2, 2);
    CHECK(nonfinite_pixels(img) == 0);
    img.rgb[4] = std::numeric_limits<float>::infinity();
    img.variance[9] = std::numeric_limits<float>::quiet_NaN();
    CHECK(nonfinite_pixels(img) == 2);
}

// ---- class 4: silently wrong input -----------------------------------------------------------

TEST_CASE("silently wrong input is refused or warned about once", "[gltf][hostile]") {
    SECTION("an index count that is not a multiple of 3") {
        Gltf g;
        g.indices = {0, 1, 2, 0};
        CHECK(refusal(g).find("4 indices are not a multiple of 3") != std::string::npos);
    }
    SECTION("baseColorFactor above 1 is clamped with one warning") {
        Gltf g;
        g.material = R"({"pbrMetallicRoughness": {"baseColorFactor": [5, 0.5, 2, 1]}})";
        const Loaded l = load(g);
        REQUIRE(l.warnings.size() == 1);
        CHECK(l.warnings[0].find("clamped") != std::string::npos);
        CHECK(l.scene.materials[0].albedo == glm::vec3(1.0f, 0.5f, 1.0f));
    }
    SECTION("wrong JSON types of known properties") {
        Gltf g;
        g.nodes = R"([{"mesh": "0"}])";
        CHECK(refusal(g).find("nodes[0].mesh: expected an integer, found a string") != std::string::npos);
        Gltf m;
        m.material = R"({"pbrMetallicRoughness": {"baseColorFactor": "red"}})";
        CHECK(refusal(m).find("baseColorFactor: expected an array of numbers") != std::string::npos);
        Gltf d;
        d.material = R"({"doubleSided": 1})";
        CHECK(refusal(d).find("doubleSided: expected a boolean") != std::string::npos);
    }
    SECTION("a projective or all-zero node matrix") {
        Gltf g;
        g.nodes = R"([{"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0.5, 0,0,0,1]}])";
        CHECK(refusal(g).find("matrix is projective") != std::string::npos);
        Gltf zero;
        zero.nodes = R"([{"mesh": 0, "matrix": [0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,1]}])";
        const Loaded l = load(zero);
        REQUIRE(l.warnings.size() == 1);
        CHECK(l.warnings[0].find("singular") != std::string::npos);
    }
    SECTION("asset.version other than 2.x") {
        for (const char* version : {"1.0", "3.0", "2", "two"}) {
            Gltf g;
            g.asset = std::string(R"("asset": {"version": ")") + version + "\"}";
            CHECK(refusal(g).find("is not 2.x") != std::string::npos);
        }
        Gltf newer;
        newer.asset = R"("asset": {"version": "2.1", "minVersion": "2.1"})";
        CHECK(refusal(newer).find("minVersion") != std::string::npos);
    }
    SECTION("coincident emitters are merged with one warning") {
        Gltf g;
        g.material = R"({"emissiveFactor": [1, 1, 1]})";
        g.nodes = R"([{"mesh": 0}, {"mesh": 0}])";
        g.scene_nodes = "[0, 1]";
        g.indices = {0, 1, 2, 1, 2, 0, 0, 2, 1};  // the same, rotated, then the back face
        const Loaded l = load(g);
        CHECK(l.scene.triangle_count() == 2);  // the front face once, the back face once
        REQUIRE(l.warnings.size() == 1);
        CHECK(l.warnings[0].find("4 emissive triangle(s) repeat another") != std::string::npos);
    }
    SECTION("coordinates beyond float traversal's reach warn once") {
        Gltf g;
        g.size = 1e12;
        const Loaded l = load(g);
        REQUIRE(l.warnings.size() == 1);
        CHECK(l.warnings[0].find("float traversal may lose triangles") != std::string::npos);
        Gltf fine;
        fine.size = 1e6;
        CHECK(load(fine).warnings.empty());
    }
}

// ---- glTF metallic-roughness factors (DESIGN.md "Radiometric contract") ----------------------

TEST_CASE("metallic-roughness factors are read, clamped with one warning, or refused",
          "[gltf][hostile][materials]") {
    SECTION("the specification's defaults: metallic 1, roughness 1, specular 1") {
        Gltf g;
        const Loaded l = load(g);
        CHECK(l.warnings.empty());
        const Material& m = l.scene.materials[0];
        CHECK(m.metallic == 1.0f);
        CHECK(m.roughness == 1.0f);
        CHECK(m.specular == 1.0f);
        CHECK(m.specular_color == glm::vec3(1.0f));
        CHECK_FALSE(m.lambertian());
    }
    SECTION("factors and KHR_materials_specular as written; specularFactor 0 is Lambertian") {
        Gltf g;
        g.material = R"({"pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.25},
                         "extensions": {"KHR_materials_specular": {"specularFactor": 0.5,
                                        "specularColorFactor": [1, 2, 0.5]}}})";
        const Material m = load(g).scene.materials[0];
        CHECK(m.metallic == 0.0f);
        CHECK(m.roughness == 0.25f);
        CHECK(m.specular == 0.5f);
        CHECK(m.specular_color == glm::vec3(1.0f, 2.0f, 0.5f));
        Gltf l;
        l.material = R"({"pbrMetallicRoughness": {"metallicFactor": 0},
                         "extensions": {"KHR_materials_specular": {"specularFactor": 0}}})";
        CHECK(load(l).scene.materials[0].lambertian());
    }
    SECTION("the default material (a primitive without one) is the specification's") {
        Gltf g;
        g.material = "{}";
        const Material m = load(g).scene.materials[0];
        CHECK(m.metallic == 1.0f);
        CHECK(m.roughness == 1.0f);
    }
    SECTION("factors outside [0, 1] are clamped with one warning each kind") {
        Gltf g;
        g.material = R"({"pbrMetallicRoughness": {"metallicFactor": 1.5, "roughnessFactor": -0.5},
                         "extensions": {"KHR_materials_specular": {"specularFactor": 3}}})";
        const Loaded l = load(g);
        CHECK(l.warnings.size() == 3);
        CHECK(std::count_if(l.warnings.begin(), l.warnings.end(), [](const std::string& w) {
                  return w.find("is outside [0, 1]; clamped") != std::string::npos;
              }) == 3);
        const Material& m = l.scene.materials[0];
        CHECK(m.metallic == 1.0f);
        CHECK(m.roughness == 0.0f);
        CHECK(m.specular == 1.0f);
    }
    SECTION("non-numbers and negative colours are refused") {
        Gltf g;
        g.material = R"({"extensions": {"KHR_materials_specular": {"specularFactor": "big"}}})";
        CHECK(refusal(g).find("specularFactor must be a finite number") != std::string::npos);
        Gltf c;
        c.material = R"({"extensions": {"KHR_materials_specular": {"specularColorFactor": [1, -1, 1]}}})";
        CHECK(refusal(c).find("specularColorFactor must be 3 finite non-negative numbers") !=
              std::string::npos);
        Gltf n;
        n.material = R"({"pbrMetallicRoughness": {"metallicFactor": "1"}})";
        CHECK(refusal(n) != "(loaded)");
    }
    SECTION("a file may require KHR_materials_specular") {
        Gltf g;
        g.extra = R"("extensionsUsed": ["KHR_materials_specular"], "extensionsRequired": ["KHR_materials_specular"],)";
        CHECK(load(g).scene.triangle_count() == 1);
    }
}
