// EXR and PNG outputs, and the atomic write beneath them (DESIGN.md "Outputs", "Exit status").
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <stb/stb_image.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/error.h"
#include "image/image.h"

namespace fs = std::filesystem;
using namespace mcrt;

namespace {

// A fresh directory per test, removed with everything in it at the end.
struct TempDir {
    fs::path path;
    TempDir() {
        static int counter = 0;
        path = fs::temp_directory_path() /
               ("mcrt_test_image-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
    std::set<std::string> entries() const {
        std::set<std::string> names;
        for (const auto& entry : fs::directory_iterator(path)) {
            names.insert(entry.path().filename().string());
        }
        return names;
    }
};

uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// Non-square with distinct values per pixel and channel, so a transposed or flipped
// read cannot pass; the first pixels hold floats that a lossy path would alter.
Image test_image() {
    Image image(5, 3);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uniform(-10.0f, 10.0f);
    for (float& v : image.rgb) v = uniform(rng);
    for (float& v : image.variance) v = std::abs(uniform(rng)) * 1e-3f;
    const float specials[] = {0.1f,
                              -0.0f,
                              std::numeric_limits<float>::denorm_min(),
                              std::numeric_limits<float>::max(),
                              std::numeric_limits<float>::infinity(),
                              std::nextafter(1.0f, 2.0f)};
    for (size_t i = 0; i < std::size(specials); ++i) image.rgb[i] = specials[i];
    image.spp = 4096;
    return image;
}

// Minimal EXR with only the named float channels, each pixel = its channel index + 1.
void write_plain_exr(const std::string& path, const std::vector<std::string>& channels) {
    const int w = 2, h = 2;
    Imf::Header header(w, h);
    std::vector<std::vector<float>> data;
    for (const auto& name : channels) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer frame_buffer;
    for (size_t c = 0; c < channels.size(); ++c) data.emplace_back(w * h, float(c + 1));
    for (size_t c = 0; c < channels.size(); ++c) {
        frame_buffer.insert(channels[c],
                            Imf::Slice::Make(Imf::FLOAT, data[c].data(), header.dataWindow()));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(h);
}

struct Png {
    int width = 0, height = 0, channels = 0;
    std::vector<uint8_t> pixels;
};

Png read_png(const std::string& path) {
    Png png;
    unsigned char* data = stbi_load(path.c_str(), &png.width, &png.height, &png.channels, 0);
    if (!data) throw std::runtime_error(path + ": " + stbi_failure_reason());
    png.pixels.assign(data, data + size_t(png.width) * png.height * png.channels);
    stbi_image_free(data);
    return png;
}

// A 1-row image whose red channel holds `values` (green, blue zero).
Image red_row(const std::vector<float>& values) {
    Image image(int(values.size()), 1);
    for (size_t i = 0; i < values.size(); ++i) image.rgb[3 * i] = values[i];
    return image;
}

std::vector<int> red_of(const Png& png) {
    std::vector<int> red;
    for (int x = 0; x < png.width; ++x) red.push_back(png.pixels[size_t(png.channels) * x]);
    return red;
}

}  // namespace

TEST_CASE("EXR round trip keeps exact float bits, variance, spp and attributes", "[image][exr]") {
    TempDir dir;
    const Image image = test_image();
    const std::string path = dir.file("out.exr");
    write_exr(path, image, {{"scene", "cornell.gltf"}, {"estimator", "mis"}});

    const Image read = read_exr(path);
    REQUIRE(read.width == image.width);
    REQUIRE(read.height == image.height);
    CHECK(read.spp == image.spp);
    REQUIRE(read.rgb.size() == image.rgb.size());
    REQUIRE(read.variance.size() == image.variance.size());
    for (size_t i = 0; i < image.rgb.size(); ++i) {
        INFO("rgb float " << i);
        CHECK(bits(read.rgb[i]) == bits(image.rgb[i]));
    }
    for (size_t i = 0; i < image.variance.size(); ++i) {
        INFO("variance float " << i);
        CHECK(bits(read.variance[i]) == bits(image.variance[i]));
    }
    CHECK(fs::exists(path));
    CHECK(dir.entries() == std::set<std::string>{"out.exr"});

    Imf::InputFile file(path.c_str());
    const auto* scene = file.header().findTypedAttribute<Imf::StringAttribute>("scene");
    REQUIRE(scene);
    CHECK(scene->value() == "cornell.gltf");
    const auto* spp = file.header().findTypedAttribute<Imf::FloatAttribute>("spp");
    REQUIRE(spp);
    CHECK(spp->value() == 4096.0f);
}

TEST_CASE("EXR header: channel names, variance layer, ZIP, row 0 at the top", "[image][exr]") {
    TempDir dir;
    const Image image = test_image();
    const std::string path = dir.file("out.exr");
    write_exr(path, image);

    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    std::set<std::string> names;
    for (auto c = header.channels().begin(); c != header.channels().end(); ++c) {
        names.insert(c.name());
        CHECK(c.channel().type == Imf::FLOAT);
    }
    CHECK(names == std::set<std::string>{"R", "G", "B", "variance.B", "variance.G", "variance.R"});
    std::set<std::string> layers;
    header.channels().layers(layers);
    CHECK(layers == std::set<std::string>{"variance"});
    CHECK(header.compression() == Imf::ZIP_COMPRESSION);
    CHECK(header.lineOrder() == Imf::INCREASING_Y);
    CHECK(header.dataWindow().min == Imath::V2i(0, 0));
    CHECK(header.dataWindow().max == Imath::V2i(image.width - 1, image.height - 1));

    // Read G through OpenEXR itself: EXR y = 0 must be Image row 0.
    std::vector<float> green(size_t(image.width) * image.height);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("G", Imf::Slice::Make(Imf::FLOAT, green.data(), header.dataWindow()));
    file.setFrameBuffer(frame_buffer);
    file.readPixels(0, image.height - 1);
    for (size_t i = 0; i < green.size(); ++i) CHECK(bits(green[i]) == bits(image.rgb[3 * i + 1]));
}

TEST_CASE("read_exr: variance is zero when the layer is absent", "[image][exr]") {
    TempDir dir;
    const std::string path = dir.file("rgb_only.exr");
    write_plain_exr(path, {"R", "G", "B"});
    const Image image = read_exr(path);
    REQUIRE(image.width == 2);
    REQUIRE(image.height == 2);
    CHECK(image.spp == 0);
    for (size_t i = 0; i < 4; ++i) {
        // ChannelList order is alphabetical, but write_plain_exr numbers by its argument order.
        CHECK(image.rgb[3 * i + 0] == 1.0f);
        CHECK(image.rgb[3 * i + 1] == 2.0f);
        CHECK(image.rgb[3 * i + 2] == 3.0f);
    }
    for (float v : image.variance) CHECK(v == 0.0f);
}

TEST_CASE("read_exr throws InputError for missing, garbage and channel-less files",
          "[image][exr]") {
    TempDir dir;
    CHECK_THROWS_AS(read_exr(dir.file("absent.exr")), InputError);
    CHECK_THROWS_WITH(read_exr(dir.file("absent.exr")), Catch::Contains("absent.exr"));

    const std::string garbage = dir.file("garbage.exr");
    std::ofstream(garbage) << "this is not an OpenEXR file";
    CHECK_THROWS_AS(read_exr(garbage), InputError);
    CHECK_THROWS_WITH(read_exr(garbage), Catch::StartsWith(garbage + ": "));

    // Truncated: a valid header whose pixel data is cut off.
    const std::string truncated = dir.file("truncated.exr");
    write_exr(truncated, test_image());
    fs::resize_file(truncated, fs::file_size(truncated) / 2);
    CHECK_THROWS_AS(read_exr(truncated), InputError);

    const std::string no_green = dir.file("no_green.exr");
    write_plain_exr(no_green, {"R", "B", "A"});
    CHECK_THROWS_AS(read_exr(no_green), InputError);
    CHECK_THROWS_WITH(read_exr(no_green), Catch::Contains("G"));
}

TEST_CASE("Writing into a missing directory throws InputError and writes nothing", "[image]") {
    TempDir dir;
    const Image image = test_image();
    const fs::path missing = dir.path / "missing";
    CHECK_THROWS_AS(write_exr((missing / "out.exr").string(), image), InputError);
    CHECK_THROWS_WITH(write_exr((missing / "out.exr").string(), image),
                      Catch::Contains("does not exist"));
    CHECK_THROWS_AS(write_png((missing / "out.png").string(), image), InputError);
    CHECK_FALSE(fs::exists(missing));
    CHECK(dir.entries().empty());
}

TEST_CASE("write_atomically: a failing writer leaves no file behind", "[image][atomic]") {
    TempDir dir;
    const std::string path = dir.file("out.bin");
    std::string temporary_seen;
    auto failing = [&](const std::string& temporary) {
        temporary_seen = temporary;
        std::ofstream(temporary) << "partial";
        throw std::runtime_error("writer failed");
    };
    CHECK_THROWS_WITH(write_atomically(path, failing), "writer failed");
    // An unnamed O_TMPFILE inode (/proc/self/fd/N), or a named sibling where that is unsupported.
    CHECK((fs::path(temporary_seen).parent_path() == dir.path ||
           temporary_seen.rfind("/proc/self/fd/", 0) == 0));
    CHECK(dir.entries().empty());

    // An existing output survives a failed rewrite untouched.
    std::ofstream(path) << "old";
    CHECK_THROWS(write_atomically(path, failing));
    CHECK(dir.entries() == std::set<std::string>{"out.bin"});
    std::ifstream in(path);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(content == "old");
}

TEST_CASE("write_atomically replaces the target and errors name the path", "[image][atomic]") {
    TempDir dir;
    const std::string path = dir.file("out.txt");
    std::ofstream(path) << "old";
    write_atomically(path, [](const std::string& temporary) { std::ofstream(temporary) << "new"; });
    CHECK(dir.entries() == std::set<std::string>{"out.txt"});
    std::ifstream in(path);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(content == "new");

    // On the named-temporary path (file systems without O_TMPFILE), a writer that removes its
    // temporary makes the rename fail with a RuntimeError naming the path.
    ::setenv("MCRT_TEST_NO_TMPFILE", "1", 1);
    auto removing = [](const std::string& temporary) { std::remove(temporary.c_str()); };
    CHECK_THROWS_AS(write_atomically(path, removing), RuntimeError);
    CHECK_THROWS_WITH(write_atomically(path, removing), Catch::StartsWith(path + ": "));
    ::unsetenv("MCRT_TEST_NO_TMPFILE");
}

TEST_CASE("PNG: exact piecewise sRGB encoding, clamping and NaN", "[image][png]") {
    TempDir dir;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    // Expected codes from IEC 61966-2-1: 12.92 x below 0.0031308, 1.055 x^(1/2.4) - 0.055 above.
    // 0.001 → 3 (a 2.2 power law would give 11); 0.0031308 → 0.0404499 → 10; 0.5 → 0.735357 → 188;
    // 0.25 → 0.537099 → 137; 0.18 → 0.461356 → 118.
    const std::vector<float> linear = {0.0f,  1.0f, 0.001f, 0.0031308f, 0.5f, 0.25f,
                                       0.18f, nan,  -1.0f,  2.0f,       inf,  -inf};
    const std::vector<int> expected = {0, 255, 3, 10, 188, 137, 118, 0, 0, 255, 255, 0};
    const std::string path = dir.file("out.png");
    write_png(path, red_row(linear));

    const Png png = read_png(path);
    REQUIRE(png.width == int(linear.size()));
    REQUIRE(png.height == 1);
    REQUIRE(png.channels == 3);
    CHECK(red_of(png) == expected);
    for (int x = 0; x < png.width; ++x) {
        CHECK(int(png.pixels[3 * x + 1]) == 0);
        CHECK(int(png.pixels[3 * x + 2]) == 0);
    }
    CHECK(dir.entries() == std::set<std::string>{"out.png"});
}

TEST_CASE("PNG: exposure +1 doubles the linear value", "[image][png]") {
    TempDir dir;
    const std::vector<float> linear = {0.25f, 0.5f, 0.0015654f, 0.09f};
    write_png(dir.file("plus1.png"), red_row(linear), 1.0f);
    std::vector<float> doubled;
    for (float v : linear) doubled.push_back(2 * v);
    write_png(dir.file("doubled.png"), red_row(doubled), 0.0f);

    const Png plus1 = read_png(dir.file("plus1.png"));
    CHECK(red_of(plus1) == red_of(read_png(dir.file("doubled.png"))));
    CHECK(red_of(plus1) == std::vector<int>{188, 255, 10, 118});
}

TEST_CASE("PNG: row 0 is the top and channels stay in RGB order", "[image][png]") {
    TempDir dir;
    Image image(2, 2);
    // Top-left red, top-right green, bottom-left blue, bottom-right white.
    const float colors[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    for (int p = 0; p < 4; ++p) {
        for (int c = 0; c < 3; ++c) image.rgb[3 * p + c] = colors[p][c];
    }
    write_png(dir.file("out.png"), image);
    const Png png = read_png(dir.file("out.png"));
    REQUIRE(png.channels == 3);
    for (int p = 0; p < 4; ++p) {
        for (int c = 0; c < 3; ++c) CHECK(int(png.pixels[3 * p + c]) == 255 * int(colors[p][c]));
    }
}
