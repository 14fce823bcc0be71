// Scenes that hang or crash the loader, values that overflow, silently wrong input
// (docs/ROBUSTNESS.md, "Hostile input"). Each refusal is one InputError (exit 2 from mcrt
// render) naming the cause; what is accepted with a warning warns once. Cases that hung or crashed
// the old loader run through the mcrt executable, so that a regression fails the test instead of
// hanging it.
#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "common/error.h"
#include "image/image_check.h"
#include "image_bytes.h"
#include "process_support.h"
#include "scene/gltf_import.h"

using namespace mcrt;
using namespace mcrt::test;
namespace fs = std::filesystem;

namespace {

// Byte offset of the texture coordinates after the positions and `index_count` indices.
size_t texcoord_offset(size_t index_count) { return (36 + 2 * index_count + 3) / 4 * 4; }

// Buffer bytes: one triangle of half-size `s` in the xz plane (front face up), then indices and,
// with `texcoords`, its corners' TEXCOORD_0.
std::string triangle_buffer_uri(double s, const std::vector<uint16_t>& indices = {0, 1, 2},
                                bool texcoords = false) {
    const float p[9] = {float(-s), 0, float(s), float(s), 0, float(s), 0, 0, float(-s)};
    const float uv[6] = {0, 0, 1, 0, 0, 1};
    std::vector<unsigned char> bytes(texcoords ? texcoord_offset(indices.size()) + sizeof uv
                                               : sizeof p + 2 * indices.size());
    std::memcpy(bytes.data(), p, sizeof p);
    std::memcpy(bytes.data() + sizeof p, indices.data(), 2 * indices.size());
    if (texcoords) std::memcpy(bytes.data() + texcoord_offset(indices.size()), uv, sizeof uv);
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
    bool texcoords = false;  // the triangle has TEXCOORD_0 (accessor 2), as textured materials read

    std::string text() const {
        const std::string uri =
            buffer_uri.empty() ? triangle_buffer_uri(size, indices, texcoords) : buffer_uri;
        const size_t uv_at = texcoord_offset(indices.size());
        const size_t length = texcoords ? uv_at + 24 : 36 + 2 * indices.size();
        const std::string uv_attribute = texcoords ? R"(, "TEXCOORD_0": 2)" : "";
        const std::string uv_accessor =
            texcoords ? R"(, {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"})"
                      : "";
        const std::string uv_view = texcoords ? R"(, {"buffer": 0, "byteOffset": )" +
                                                    std::to_string(uv_at) + R"(, "byteLength": 24})"
                                              : "";
        return "{" + asset + "," + extra + R"("scene": 0, "scenes": [{"nodes": )" + scene_nodes +
               R"(}], "nodes": )" + nodes + R"(, "materials": [)" + material +
               R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0)" + uv_attribute +
               R"(}, "indices": 1, "material": 0}]}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": )" +
               std::to_string(indices.size()) + R"(, "type": "SCALAR"})" + uv_accessor + R"(],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": )" +
               std::to_string(2 * indices.size()) + "}" + uv_view + R"(],
  "buffers": [{"byteLength": )" +
               std::to_string(length) + R"(, "uri": ")" + uri + R"("}]})";
    }
};

struct Loaded {
    Scene scene;
    std::vector<std::string> warnings;
};

Loaded load(const Gltf& g) {
    Loaded result;
    const std::string text = g.text();
    result.scene =
        load_gltf_from_memory("test.gltf", std::vector<unsigned char>(text.begin(), text.end()),
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
    const ProcessResult r = run_process(MCRT_EXE,
                                        {"render", scene, "--width", "8", "--height", "8", "--spp",
                                         "16", "--quiet", "--out", logs / "a.exr"},
                                        logs.path(), 30);
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
    require_render_refused(dir / "fifo.gltf",
                           "is a FIFO (named pipe); only regular files are read");
    g.buffer_uri = "dir.bin";
    write_text(dir / "dir.gltf", g.text());
    require_render_refused(dir / "dir.gltf", "is a directory; only regular files are read");
    g.buffer_uri = "missing.bin";
    write_text(dir / "missing.gltf", g.text());
    require_render_refused(dir / "missing.gltf", "missing.bin : no such file");
    // An image uri (tinygltf reads every image file, used or not) is no exception.
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
    g.extra =
        R"("extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],)";
    CHECK(refusal(g).find("extensionsRequired names KHR_draco_mesh_compression") !=
          std::string::npos);
    g.extra =
        R"("extensionsUsed": ["KHR_materials_emissive_strength"], "extensionsRequired": ["KHR_materials_emissive_strength"],)";
    CHECK(load(g).scene.triangle_count() == 1);
}

TEST_CASE("a hierarchy expanding to 2^30 node instances is refused before expanding",
          "[gltf][hostile]") {
    // Node i lists node i + 1 twice: 2^31 − 1 instances from 31 nodes.
    std::string nodes = "[";
    for (int i = 0; i < 31; ++i) {
        nodes += i < 30 ? "{\"children\": [" + std::to_string(i + 1) + ", " +
                              std::to_string(i + 1) + "]},"
                        : "{\"mesh\": 0}";
    }
    Gltf g;
    g.nodes = nodes + "]";
    const std::string why = refusal(g);
    CHECK(why.find("expands to 2.14748e+09 node instances, more than 16777216") !=
          std::string::npos);
    // Many instances of a big mesh: refused by the triangle bound, before expanding.
    std::string few = "[";
    for (int i = 0; i < 15; ++i)
        few += i < 14 ? "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) +
                            "]},"
                      : "{\"mesh\": 0}";
    Gltf big;
    big.nodes = few + "]";
    big.indices.assign(30000, 0);  // 10,000 (degenerate) triangles × 16,384 instances
    CHECK(refusal(big).find("triangles, more than") != std::string::npos);
}

TEST_CASE("textured scenes with damaged images or references are refused in one line",
          "[gltf][hostile][textures]") {
    TempDir dir("mcrt-hostile");
    Gltf g;
    g.texcoords = true;
    g.material = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})";
    auto scene_with = [&](const std::string& name, const std::string& images,
                          const std::string& textures = R"([{"source": 0}])") {
        Gltf s = g;
        s.extra = R"("images": )" + images + R"(, "textures": )" + textures + ",";
        write_text(dir / name, s.text());
        return dir / name;
    };
    // A 1×1 grey PNG, then cut before its end.
    const std::vector<unsigned char> png = png_file(1, 8, 0, {{128}});
    write_text(dir / "truncated.png", std::string(png.begin(), png.end() - 20));
    require_render_refused(scene_with("truncated.gltf", R"([{"uri": "truncated.png"}])"),
                           "image 0 (truncated.png): the PNG is truncated");
    // 65536 × 65536 declared by a valid IHDR, then garbage: refused before any texel is allocated.
    std::vector<unsigned char> huge = png_signature();
    const std::vector<unsigned char> ihdr = png_ihdr(65536, 65536, 8, 6);
    huge.insert(huge.end(), ihdr.begin(), ihdr.end());
    huge.insert(huge.end(), 100, 0xA5);
    write_text(dir / "huge.png", std::string(huge.begin(), huge.end()));
    require_render_refused(
        scene_with("huge.gltf", R"([{"uri": "huge.png"}])"),
        "image 0 (huge.png): 65536 × 65536 texels: more than the 16384 per side");
    // An image uri naming a directory.
    fs::create_directory(dir / "dir.png");
    require_render_refused(scene_with("dir.gltf", R"([{"uri": "dir.png"}])"),
                           "dir.png: is a directory; only regular files are read");
    // Texture and image indices out of range.
    write_text(dir / "good.png", std::string(png.begin(), png.end()));
    require_render_refused(scene_with("texture_range.gltf", R"([{"uri": "good.png"}])", "[]"),
                           "material 0 baseColorTexture: texture 0 out of range");
    require_render_refused(
        scene_with("image_range.gltf", R"([{"uri": "good.png"}])", R"([{"source": 1}])"),
        "texture 0: source image 1 out of range");
    // A damaged byte (the texel of a stored block): named by its chunk's CRC.
    std::vector<unsigned char> damaged = png;
    damaged[33 + 8 + 7 + 1] ^= 0x01;
    write_text(dir / "damaged.png", std::string(damaged.begin(), damaged.end()));
    require_render_refused(scene_with("damaged.gltf", R"([{"uri": "damaged.png"}])"),
                           "image 0 (damaged.png): PNG chunk IDAT at byte 33: CRC mismatch");
    // 1 × 1 declared, 64 MiB of zeros deflated to 64 KiB: refused before stb_image inflates it.
    std::vector<unsigned char> zeros(size_t(64) << 20, 0);
    uLongf deflated_size = compressBound(uLong(zeros.size()));
    std::vector<unsigned char> deflated(deflated_size);
    REQUIRE(compress2(deflated.data(), &deflated_size, zeros.data(), uLong(zeros.size()), 9) ==
            Z_OK);
    deflated.resize(deflated_size);
    std::vector<unsigned char> bomb = png_signature();
    for (const std::vector<unsigned char>& chunk :
         {png_ihdr(1, 1, 8, 0), png_chunk("IDAT", deflated), png_chunk("IEND", {})})
        bomb.insert(bomb.end(), chunk.begin(), chunk.end());
    write_text(dir / "bomb.png", std::string(bomb.begin(), bomb.end()));
    require_render_refused(scene_with("bomb.gltf", R"([{"uri": "bomb.png"}])"),
                           "image 0 (bomb.png): the PNG's IDAT data inflates beyond the 2 bytes "
                           "its 1 × 1 texels need");
    // A KTX2 image (KHR_texture_basisu's): named by its extension.
    const std::string ktx2 = "\xABKTX 20\xBB\r\n\x1A\n" + std::string(52, '\0');
    write_text(dir / "image.ktx2", ktx2);
    require_render_refused(
        scene_with("ktx2.gltf", R"([{"uri": "image.ktx2", "mimeType": "image/ktx2"}])"),
        "image 0 (image.ktx2): an image of KHR_texture_basisu (image/ktx2), which mcrt does not "
        "implement");
}

// ---- class 3: values that overflow ------------------------------------------------------------

TEST_CASE("radiance that cannot be summed in single precision is refused", "[gltf][hostile]") {
    Gltf g;
    g.material =
        R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e31}}})";
    CHECK(refusal(g).find("emission 1e+31 exceeds 1e+30") != std::string::npos);
    // Each instance's power is a float, their sum is not: 16 instances of 6e37.
    Gltf many;
    many.size = 1e11;
    many.material =
        R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e15}}})";
    std::string nodes = "[", roots = "[";
    for (int i = 0; i < 16; ++i) {
        nodes += std::string(i ? "," : "") + "{\"mesh\": 0, \"translation\": [0, " +
                 std::to_string(i) + "e10, 0]}";
        roots += std::string(i ? "," : "") + std::to_string(i);
    }
    many.nodes = nodes + "]";
    many.scene_nodes = roots + "]";
    CHECK(refusal(many).find("summed power") != std::string::npos);
}

TEST_CASE("a sky that overflows is refused, and non-finite pixels are counted", "[cli][hostile]") {
    TempDir logs("mcrt-hostile-logs");
    const ProcessResult r =
        run_process(MCRT_EXE,
                    {"render", std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf",
                     "--estimator", "ambient-cosine", "--sky", "1e38", "--width", "8", "--height",
                     "8", "--quiet", "--out", logs / "a.exr"},
                    logs.path(), 60);
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
        CHECK(refusal(g).find(
                  "nodes[0].mesh: expected an integer from 0 to 2147483647, found a string") !=
              std::string::npos);
        Gltf m;
        m.material = R"({"pbrMetallicRoughness": {"baseColorFactor": "red"}})";
        CHECK(refusal(m).find("baseColorFactor: expected an array of numbers") !=
              std::string::npos);
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

// ---- indices that wrap: integers beyond what tinygltf keeps them in ---------------------------

// `text` with its first `from` replaced by `to` (which must be there), loaded from memory: the
// refusal, or "(loaded)".
std::string refusal_of_edit(const std::string& text, const std::string& from,
                            const std::string& to) {
    std::string edited = text;
    const size_t at = edited.find(from);
    REQUIRE(at != std::string::npos);
    edited.replace(at, from.size(), to);
    try {
        load_gltf_from_memory("test.gltf", std::vector<unsigned char>(edited.begin(), edited.end()),
                              [](const std::string&) {});
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

TEST_CASE("integers that tinygltf would wrap, drop or turn negative are refused naming them",
          "[gltf][hostile]") {
    // tinygltf 2.7 casts an integer property to int (2^32 + 1 reads as 1, another valid index),
    // reads a size_t property written negative or as 4.0 as absent, and keeps an extension's
    // integers in an int: each must be refused before it parses, naming the property.
    Gltf two;  // two materials, so that a wrapped material index lands on a valid one
    two.material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
                      {"emissiveFactor": [1, 1, 1]})";
    const std::string text = two.text();
    REQUIRE(refusal_of_edit(text, R"("material": 0)", R"("material": 1)") == "(loaded)");
    struct Case {
        const char* from;
        const char* to;
        const char* needle;
    };
    const Case cases[] = {
        {R"("material": 0)", R"("material": 4294967297)",
         "meshes[0].primitives[0].material: expected an integer from 0 to 2147483647, found "
         "4294967297"},
        {R"("material": 0)", R"("material": -1)",
         "primitives[0].material: expected an integer from 0"},
        {R"("material": 0)", R"("material": 1.0)",
         "primitives[0].material: expected an integer from 0 to 2147483647, found 1.0"},
        {R"("material": 0)", R"("material": 18446744073709551617)",
         "primitives[0].material: expected an integer"},
        {R"("indices": 1)", R"("indices": 4294967297)",
         "primitives[0].indices: expected an integer from 0"},
        {R"("POSITION": 0)", R"("POSITION": 4294967296)",
         "primitives[0].attributes.POSITION: expected an integer from 0"},
        {R"({"mesh": 0})", R"({"mesh": 4294967296})",
         "nodes[0].mesh: expected an integer from 0 to 2147483647, found 4294967296"},
        {R"({"mesh": 0})", R"({"mesh": 0, "camera": 4294967296})",
         "nodes[0].camera: expected an integer from 0"},
        {R"({"mesh": 0})", R"({"mesh": 0, "skin": -4294967296})",
         "nodes[0].skin: expected an integer from 0"},
        {R"({"mesh": 0})", R"({"mesh": 0, "children": [4294967297]})",
         "nodes[0].children[0]: expected an integer from 0"},
        {R"("nodes": [0])", R"("nodes": [4294967296])",
         "scenes[0].nodes[0]: expected an integer from 0"},
        {R"("scene": 0)", R"("scene": 4294967296)", "glTF.scene: expected an integer from 0"},
        {R"({"bufferView": 0, "componentType": 5126)",
         R"({"bufferView": 4294967296, "componentType": 5126)",
         "accessors[0].bufferView: expected an integer from 0"},
        {R"({"bufferView": 0, "componentType": 5126)",
         R"({"bufferView": 0, "byteOffset": -12, "componentType": 5126)",
         "accessors[0].byteOffset: expected a non-negative integer, found -12"},
        {R"("componentType": 5126)", R"("componentType": 5126.0)",
         "accessors[0].componentType: expected a non-negative integer, found 5126.0"},
        {R"("buffer": 0, "byteOffset": 0)", R"("buffer": 4294967296, "byteOffset": 0)",
         "bufferViews[0].buffer: expected an integer from 0"},
        {R"("buffer": 0, "byteOffset": 0)", R"("buffer": 0, "byteStride": 12.0, "byteOffset": 0)",
         "bufferViews[0].byteStride: expected a non-negative integer"},
        {R"("buffer": 0, "byteOffset": 0)", R"("buffer": 0, "target": 4294967296, "byteOffset": 0)",
         "bufferViews[0].target: expected an integer from -2147483648 to 2147483647"},
        {R"("indices": 1)", R"("indices": 1, "mode": 4294967300)",
         "primitives[0].mode: expected an integer from -2147483648"},
        {R"("indices": 1)", R"("indices": 1, "targets": [{"POSITION": 4294967296}])",
         "primitives[0].targets[0].POSITION: expected an integer from 0"},
        {R"("scene": 0,)", R"("scene": 0, "skins": [{"joints": [0, 4294967296]}],)",
         "skins[0].joints[1]: expected an integer from 0"},
        {R"("scene": 0,)",
         R"("scene": 0, "animations": [{"channels": [{"sampler": 0, "target": {"node": 4294967296}}]}],)",
         "animations[0].channels[0].target.node: expected an integer from 0"},
        {R"("scene": 0,)", R"("scene": 0, "textures": [{"source": 4294967296}],)",
         "textures[0].source: expected an integer from 0"},
        {R"("scene": 0,)", R"("scene": 0, "textures": [{"sampler": 4294967296}],)",
         "textures[0].sampler: expected an integer from 0"},
        {R"("scene": 0,)", R"("scene": 0, "images": [{"bufferView": 4294967296}],)",
         "images[0].bufferView: expected an integer from 0"},
        {R"("scene": 0,)", R"("scene": 0, "samplers": [{"wrapS": 4294977793}],)",
         "samplers[0].wrapS: expected an integer from -2147483648"},
        {R"("scene": 0,)", R"("scene": 0, "samplers": [{"magFilter": 4294976025}],)",
         "samplers[0].magFilter: expected an integer"},
        {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})",
         R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 4294967296}}})",
         "materials[0].pbrMetallicRoughness.baseColorTexture.index: expected an integer from 0"},
        {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})",
         R"({"normalTexture": {"index": 0, "texCoord": 4294967297}})",
         "materials[0].normalTexture.texCoord: expected an integer from 0 to 2147483647, found "
         "4294967297"},
        {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})",
         R"({"emissiveTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 4294967296}}}})",
         "materials[0].emissiveTexture.extensions.KHR_texture_transform.texCoord: expected an "
         "integer from 0"},
        {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})",
         R"({"occlusionTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0, 4294967296]}}}})",
         "materials[0].occlusionTexture.extensions.KHR_texture_transform.offset[1]: expected a "
         "number, as an "
         "integer from -2147483648 to 2147483647"},
        {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})",
         R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4294967297}}})",
         "materials[0].extensions.KHR_materials_emissive_strength.emissiveStrength: expected a "
         "number"},
        {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}})",
         R"({"extensions": {"KHR_materials_specular": {"specularColorFactor": [1, 1, -4294967295]}}})",
         "KHR_materials_specular.specularColorFactor[2]: expected a number"},
        {R"("byteLength": 36})", R"("byteLength": -36})",
         "bufferViews[0].byteLength: expected a non-negative integer"},
    };
    SECTION("every index, count and enumeration tinygltf parses, in the core and in extensions") {
        for (const Case& c : cases) {
            INFO(c.to);
            const std::string why = refusal_of_edit(text, c.from, c.to);
            CHECK(why.find(c.needle) != std::string::npos);
            CHECK(why.rfind("test.gltf: ", 0) == 0);
        }
    }
    SECTION("sparse accessors: count and offsets are ints") {
        const std::string sparse =
            R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "sparse": )";
        CHECK(refusal_of_edit(
                  text, R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"})",
                  sparse +
                      R"({"count": 4294967297, "indices": {"bufferView": 1, "componentType": 5123},
                                           "values": {"bufferView": 0}}})")
                  .find("accessors[0].sparse.count: expected an integer from 0") !=
              std::string::npos);
        CHECK(
            refusal_of_edit(
                text, R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"})",
                sparse +
                    R"({"count": 1, "indices": {"bufferView": 1, "byteOffset": 4294967296, "componentType": 5123},
                                           "values": {"bufferView": 0}}})")
                .find("accessors[0].sparse.indices.byteOffset: expected an integer from 0") !=
            std::string::npos);
        CHECK(refusal_of_edit(
                  text, R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"})",
                  sparse + R"({"count": 1, "indices": {"bufferView": 1, "componentType": 5123},
                                           "values": {"bufferView": 4294967296}}})")
                  .find("accessors[0].sparse.values.bufferView: expected an integer from 0") !=
              std::string::npos);
    }
    SECTION("what tinygltf keeps whole still loads") {
        // The largest int, as an index, is out of range rather than wrapped.
        CHECK(refusal_of_edit(text, R"("material": 0)", R"("material": 2147483647)")
                  .find("material 2147483647 out of range") != std::string::npos);
        // An extension's large number written with a fraction is a double, kept whole.
        Gltf offset;
        offset.texcoords = true;
        offset.extra = R"("images": [{"uri": ")" +
                       data_uri("image/png", png_file(1, 8, 0, {{128}})) +
                       R"("}], "textures": [{"source": 0}],)";
        offset.material = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
            "extensions": {"KHR_texture_transform": {"offset": [4294967296.0, -2147483648]}}}}})";
        const Loaded l = load(offset);
        CHECK(l.scene.materials[0].base_color_texture.row_u.z == 4294967296.0f);
        CHECK(l.scene.materials[0].base_color_texture.row_v.z == -2147483648.0f);
    }
    SECTION("mcrt render exits 2 with one line") {
        TempDir dir("mcrt-hostile");
        std::string wrapped = text;
        wrapped.replace(wrapped.find(R"("material": 0)"), 13, R"("material": 4294967297)");
        write_text(dir / "wrapped.gltf", wrapped);
        require_render_refused(
            dir / "wrapped.gltf",
            "wrapped.gltf: meshes[0].primitives[0].material: expected an integer "
            "from 0 to 2147483647, found 4294967297");
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
        c.material =
            R"({"extensions": {"KHR_materials_specular": {"specularColorFactor": [1, -1, 1]}}})";
        CHECK(refusal(c).find("specularColorFactor must be 3 finite non-negative numbers") !=
              std::string::npos);
        Gltf n;
        n.material = R"({"pbrMetallicRoughness": {"metallicFactor": "1"}})";
        CHECK(refusal(n) != "(loaded)");
    }
    SECTION("a file may require KHR_materials_specular") {
        Gltf g;
        g.extra =
            R"("extensionsUsed": ["KHR_materials_specular"], "extensionsRequired": ["KHR_materials_specular"],)";
        CHECK(load(g).scene.triangle_count() == 1);
    }
}
