// Files that a glTF's uris name (docs/ROBUSTNESS.md "Inputs that hang or crash the loader" and
// "Counts, URIs and exit statuses"): sizes checked before a byte is read, absolute paths and
// percent-encoded references read, uri schemes refused in one line.
#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "process_support.h"
#include "render/plan.h"
#include "scene/gltf_import.h"
#include "scene/gltf_uris.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;
namespace fs = std::filesystem;

namespace {

// One triangle (36 bytes of positions, 6 of indices) in a buffer of `byte_length` bytes.
std::vector<unsigned char> triangle_bytes(size_t byte_length) {
    const float p[9] = {-1, 0, 1, 1, 0, 1, 0, 0, -1};
    const uint16_t i[3] = {0, 1, 2};
    std::vector<unsigned char> bytes(byte_length);
    std::memcpy(bytes.data(), p, sizeof p);
    std::memcpy(bytes.data() + sizeof p, i, sizeof i);
    return bytes;
}

// A scene whose buffer 0 is `uri` with `byte_length`, with `images` as its "images" array.
std::string scene_text(const std::string& uri, size_t byte_length = 120,
                       const std::string& images = "") {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": 6}],)" +
           (images.empty() ? "" : R"("images": )" + images + ",") +
           R"("buffers": [{"byteLength": )" + std::to_string(byte_length) + R"(, "uri": ")" + uri +
           R"("}]})";
}

void write_file(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}
void write_file(const fs::path& path, const std::vector<unsigned char>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::string refusal(const std::string& path) {
    try {
        load_gltf(path, [](const std::string&) {});
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

}  // namespace

TEST_CASE("a buffer file is read up to its byteLength, never whole", "[gltf][hostile]") {
    TempDir dir("mcrt-resources");
    // 3 GiB, sparse: costs nothing unless read, and a loader that read it whole would take
    // seconds and gigabytes.
    write_file(dir / "big.bin", triangle_bytes(120));
    fs::resize_file(dir / "big.bin", 3ull << 30);
    write_file(dir / "big.gltf", scene_text("big.bin"));
    std::vector<std::string> files;
    FileBundle record;
    const Scene scene = load_gltf(
        dir / "big.gltf", [](const std::string&) {}, &files, &record);
    CHECK(scene.triangle_count() == 1);
    REQUIRE(record.count(dir / "big.bin"));
    CHECK(record[dir / "big.bin"].size() == 120);  // glTF 2.0 "Buffers": a longer file is valid

    // A file shorter than its byteLength is refused naming both sizes, before it is read.
    write_file(dir / "short.bin", triangle_bytes(100));
    write_file(dir / "short.gltf", scene_text("short.bin"));
    CHECK(refusal(dir / "short.gltf") ==
          dir / "short.gltf" +
              ": buffer 0: uri 'short.bin': holds 100 bytes, fewer than the 120 declared by its "
              "byteLength");
}

TEST_CASE("an image file is refused from its size before it is read", "[gltf][hostile]") {
    TempDir dir("mcrt-resources");
    write_file(dir / "a.bin", triangle_bytes(120));
    write_file(dir / "huge.png", std::string("\x89PNG\r\n\x1a\n"));
    fs::resize_file(dir / "huge.png", 3ull << 30);
    write_file(dir / "image.gltf", scene_text("a.bin", 120, R"([{"uri": "huge.png"}])"));
    CHECK(
        refusal(dir / "image.gltf") ==
        dir / "image.gltf" +
            ": image 0: uri 'huge.png': holds 3221225472 bytes, more than the 1073741824 allowed");
}

TEST_CASE("absolute and percent-encoded uris name their files", "[gltf][hostile]") {
    TempDir dir("mcrt-resources");
    fs::create_directory(dir / "sub");
    write_file(dir / "a+b c.bin", triangle_bytes(120));
    // Absolute (ROBUSTNESS.md "Deliberately accepted"), from another directory.
    write_file((dir.path() / "sub" / "absolute.gltf").string(), scene_text(dir / "a+b%20c.bin"));
    CHECK(refusal((dir.path() / "sub" / "absolute.gltf").string()) == "(loaded)");
    // RFC 3986 percent-encoding: '+' is itself, "%20" a space (tinygltf read '+' as a space).
    write_file(dir / "encoded.gltf", scene_text("a+b%20c.bin"));
    std::vector<std::string> files;
    load_gltf(
        dir / "encoded.gltf", [](const std::string&) {}, &files);
    CHECK(files == std::vector<std::string>{dir / "encoded.gltf", dir / "a+b c.bin"});
    // A missing absolute file is named as written, not joined to the scene's directory.
    write_file(dir / "missing.gltf", scene_text(dir / "missing.bin"));
    const std::string missing = refusal(dir / "missing.gltf");
    CHECK(missing.find(" " + dir / "missing.bin : no such file") != std::string::npos);
    CHECK(missing.find("//") == std::string::npos);
}

TEST_CASE("a uri with a scheme other than data: is refused naming it", "[gltf][hostile][cli]") {
    CHECK(gltf::uri_scheme("http://x/a.bin") == "http");
    CHECK(gltf::uri_scheme("HTTPS://x/a.bin") == "https");
    CHECK(gltf::uri_scheme("file:///a.bin") == "file");
    CHECK(gltf::uri_scheme("a.bin").empty());
    CHECK(gltf::uri_scheme("./a:b.bin").empty());
    CHECK(gltf::uri_scheme("/abs/a:b.bin").empty());
    CHECK(gltf::uri_scheme("1a:b").empty());
    CHECK(gltf::percent_decode("a%20b%2Bc+d%zz%4") == "a b+c+d%zz%4");

    TempDir dir("mcrt-resources");
    write_file(dir / "a.bin", triangle_bytes(120));
    for (const std::string& uri :
         std::vector<std::string>{"http://x/a.bin", "https://x/a.bin", "file://" + dir / "a.bin"}) {
        write_file(dir / "scheme.gltf", scene_text(uri));
        const std::string scheme = uri.substr(0, uri.find(':'));
        const ProcessResult r = run_process(MCRT_EXE,
                                            {"render", dir / "scheme.gltf", "--width", "8",
                                             "--height", "8", "--quiet", "--out", dir / "a.exr"},
                                            dir.path(), 30);
        CHECK(r.exit_code == 2);
        CHECK(r.err == "mcrt: error: " + dir / "scheme.gltf" + ": buffer 0: uri '" + uri +
                           "': the " + scheme +
                           " scheme is not supported (only relative paths, absolute paths and "
                           "data: URIs)\n");
    }
    // Images too, used or not.
    write_file(dir / "image.gltf", scene_text("a.bin", 120, R"([{"uri": "https://x/t.png"}])"));
    CHECK(refusal(dir / "image.gltf").find("image 0: uri 'https://x/t.png': the https scheme") !=
          std::string::npos);
}

// ---- what ran out, named: memory limits and PoCL's environment ------------------------------

namespace {

// `mcrt ARGS` through /bin/sh with `prefix` before it ("ulimit -v N;", "POCL_DEVICES=x").
ProcessResult run_mcrt_shell(const TempDir& dir, const std::string& prefix,
                             const std::string& args) {
    return run_process("/bin/sh", {"-c", prefix + " exec '" + MCRT_EXE + "' " + args}, dir.path(),
                       60);
}

}  // namespace

TEST_CASE("out of host memory while loading a scene is a runtime failure naming it",
          "[gltf][hostile][cli]") {
#if defined(__SANITIZE_ADDRESS__)
    skip_test("AddressSanitizer reserves terabytes of address space: no ulimit -v lets mcrt start");
#endif
    TempDir dir("mcrt-resources");
    write_file(dir / "a.bin", triangle_bytes(120));
    fs::resize_file(dir / "a.bin", 1ull << 30);
    write_file(dir / "huge.gltf", scene_text("a.bin", size_t(1) << 30));
    // 400 MiB of address space: mcrt starts, a 1 GiB buffer cannot be had (it was "std::bad_alloc"
    // as an input error, exit 2).
    const ProcessResult r =
        run_mcrt_shell(dir, "ulimit -v 409600;",
                       "render '" + dir / "huge.gltf" + "' --quiet --out '" + dir / "a.exr" + "'");
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err == "mcrt: error: out of host memory while loading the scene\n");
}

TEST_CASE("no device found says why: POCL_DEVICES, a memory limit", "[cli][hostile]") {
    TempDir dir("mcrt-resources");
    ProcessResult r = run_mcrt_shell(dir, "POCL_DEVICES=nonsense", "devices");
    CHECK(r.exit_code == 1);
    CHECK(
        r.err.rfind("mcrt: error: no OpenCL device found: POCL_DEVICES='nonsense' names no device "
                    "type PoCL has (nonsense); it accepts a space-separated list of ",
                    0) == 0);
    CHECK(r.err.find("pthread") != std::string::npos);
    CHECK(lines_starting_with(r.err, "mcrt:").size() == 1);
    // 150 MiB: mcrt starts, PoCL's LLVM cannot be mapped.
    r = run_mcrt_shell(dir, "ulimit -v 153600;", "devices");
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("cannot be loaded: ") != std::string::npos);
    CHECK(r.err.find("the address-space limit (ulimit -v) is 150 MiB\n") != std::string::npos);
    CHECK(lines_starting_with(r.err, "mcrt:").size() == 1);
}

TEST_CASE("POCL_CACHE_DIR naming a file fails the kernel build naming it", "[cli][hostile]") {
    TempDir dir("mcrt-resources");
    write_file(dir / "file", std::string("x"));
    const ProcessResult r =
        run_mcrt_shell(dir, "POCL_CACHE_DIR='" + dir / "file" + "'",
                       "render '" MCRT_SCENES
                       "/cornell/CornellBox-Original.gltf' --width 8 --height 8 --quiet --out '" +
                           dir / "a.exr" + "'");
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("kernel build failed on '") == 13);
    CHECK(r.err.find("': PoCL's kernel cache directory " + dir / "file" + " cannot be created (" +
                     dir / "file" +
                     " is not a directory); set POCL_CACHE_DIR to a writable directory\n") !=
          std::string::npos);
    CHECK(lines_starting_with(r.err, "mcrt:").size() == 1);
}

TEST_CASE("variants, devices and bench fail when stdout is full or closed", "[cli][hostile]") {
    TempDir dir("mcrt-resources");
    const std::string bench =
        "bench '" MCRT_SCENES
        "/cornell/CornellBox-Original.gltf' --width 8 --height 8 --repeats 1 --rays primary";
    for (const std::string command : {"variants --json", "variants", "devices", bench.c_str()}) {
        INFO(command);
        ProcessResult r = run_mcrt_shell(dir, "", command + " >/dev/full");
        CHECK(r.exit_code == 1);
        CHECK(r.err == "mcrt: error: cannot write to stdout: No space left on device\n");
        r = run_mcrt_shell(dir, "", command + " >&-");
        CHECK(r.exit_code == 1);
        CHECK(r.err == "mcrt: error: cannot write to stdout: it is closed\n");
    }
}

TEST_CASE("a triangle strip or fan of fewer than 3 is refused like TRIANGLES of 5",
          "[gltf][hostile]") {
    TempDir dir("mcrt-resources");
    write_file(dir / "a.bin", triangle_bytes(120));
    for (const int mode : {5, 6}) {
        std::string text = scene_text("a.bin");
        // Two of the three indices, as a strip (5) or a fan (6).
        text.replace(text.find(R"("count": 3, "type": "SCALAR")"), 28,
                     R"("count": 2, "type": "SCALAR")");
        text.replace(text.find(R"("indices": 1)"), 12,
                     R"("indices": 1, "mode": )" + std::to_string(mode));
        write_file(dir / "strip.gltf", text);
        CHECK(refusal(dir / "strip.gltf") ==
              dir / "strip.gltf" +
                  ": mesh 0 primitive 0: 2 indices are fewer than one triangle's 3 (mode " +
                  (mode == 5 ? "TRIANGLE_STRIP" : "TRIANGLE_FAN") + ")");
    }
}

TEST_CASE("experiment and bench scripts refuse an --out naming a file in argparse's style",
          "[scripts][hostile]") {
    TempDir dir("mcrt-resources");
    write_file(dir / "file", std::string("x"));
    for (const char* script :
         {"scripts/experiments/experiment.py", "scripts/experiments/light_select_table.py",
          "scripts/experiments/path_depths.py", "scripts/experiments/pixel_maps.py",
          "scripts/experiments/veach_mis.py", "scripts/experiments/textured_gallery.py",
          "scripts/experiments/textured_mitsuba.py", "bench/bench_paths.py",
          "bench/bench_vs_mitsuba.py"}) {
        INFO(script);
        const std::string name = fs::path(script).filename().string();
        const ProcessResult r = run_process("/usr/bin/python3",
                                            {std::string(MCRT_SOURCE_DIR) + "/" + script,
                                             MCRT_SCENES "/cornell/CornellBox-Original.gltf",
                                             "--estimators", "light-area", "--out", dir / "file"},
                                            dir.path(), 60);
        CHECK(r.exit_code == 2);
        CHECK(r.err.find("Traceback") == std::string::npos);
        CHECK(r.err.find(name + ": error: argument --out: " + dir / "file" +
                         " is a file, not a directory\n") != std::string::npos);
    }
}

TEST_CASE("the camera option names glTF camera K, an orthographic one refused", "[gltf][cli]") {
    TempDir dir("mcrt-resources");
    write_file(dir / "a.bin", triangle_bytes(120));
    std::string text = scene_text("a.bin");
    // cameras: 0 orthographic, 1 and 2 perspective, 3 on no node; nodes list camera 2 first.
    text.replace(
        text.find(R"("nodes": [{"mesh": 0}])"), 22,
        R"("cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}},
                {"name": "one", "type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
                {"name": "two", "type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1}},
                {"name": "three", "type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
  "nodes": [{"mesh": 0}, {"camera": 2, "translation": [0, 1, 3]}, {"camera": 0}, {"camera": 1, "translation": [0, 1, 4]}])");
    text.replace(text.find(R"("scenes": [{"nodes": [0]}])"), 26,
                 R"("scenes": [{"nodes": [0, 1, 2, 3]}])");
    write_file(dir / "cameras.gltf", text);
    const Scene scene = load_gltf(dir / "cameras.gltf", [](const std::string&) {});
    auto chosen = [&](int k) {
        CameraChoice choice;
        choice.index = k;
        return choose_camera(scene, choice);
    };
    auto refusal_of = [&](int k) {
        try {
            chosen(k);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("(chosen)");
    };
    CHECK(choose_camera(scene, CameraChoice{}).name == "two");  // the first camera node
    CHECK(chosen(1).name == "one");  // it was "two": the second perspective node counted
    CHECK(chosen(2).name == "two");
    CHECK(refusal_of(0).find("camera 0 of " + dir / "cameras.gltf" +
                             " is orthographic; only perspective cameras are rendered") !=
          std::string::npos);
    CHECK(refusal_of(3).find("camera 3 of " + dir / "cameras.gltf" +
                             " is on no node of the default scene") != std::string::npos);
    CHECK(refusal_of(4).find(dir / "cameras.gltf" + " has 4 cameras (0 to 3)") !=
          std::string::npos);
}
