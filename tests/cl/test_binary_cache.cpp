// The on-disk kernel binary cache: hits, misses, keys, and that it never fails a build.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "cl/binary_cache.h"
#include "cl/build_child.h"
#include "cl/cl_error.h"
#include "cl/pocl_binary.h"
#include "cl/program.h"
#include "device_support.h"
#include "render/renderer.h"
#include "render/variants.h"

using namespace mcrt;
using mcrt::test::first_device;
namespace fs = std::filesystem;

namespace {

// Sets environment variables for one test case and restores the previous values on exit.
class ScopedEnv {
  public:
    void set(const char* name, const std::string& value) {
        remember(name);
        setenv(name, value.c_str(), 1);
    }
    void unset(const char* name) {
        remember(name);
        unsetenv(name);
    }
    ~ScopedEnv() {
        for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
            if (it->second)
                setenv(it->first.c_str(), it->second->c_str(), 1);
            else
                unsetenv(it->first.c_str());
        }
    }

  private:
    void remember(const char* name) {
        const char* old = std::getenv(name);
        saved_.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
    }
    std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

// A fresh cache directory, removed at the end of the test; MCRT_CACHE_DIR points at it.
struct TempCache {
    ScopedEnv env;
    fs::path dir;
    TempCache() {
        dir = fs::temp_directory_path() / ("mcrt_binary_cache_test-" + std::to_string(::getpid()) +
                                           "-" + std::to_string(counter()++));
        fs::remove_all(dir);
        env.set("MCRT_CACHE_DIR", dir.string());
        env.unset("MCRT_NO_KERNEL_CACHE");
    }
    ~TempCache() {
        std::error_code ec;
        fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(dir, ec);
    }
    static int& counter() {
        static int n = 0;
        return n;
    }
    std::vector<fs::path> files() const {
        std::vector<fs::path> out;
        std::error_code ec;
        if (!fs::is_directory(dir, ec)) return out;
        for (const auto& entry : fs::directory_iterator(dir)) out.push_back(entry.path());
        return out;
    }
};

// x[i] = i * SCALE + OFFSET: the options change the result, so a binary built with other
// options would show in the output.
const std::string kSource =
    "kernel void affine(global float* x) {\n"
    "    size_t i = get_global_id(0);\n"
    "    x[i] = (float)i * SCALE + OFFSET;\n"
    "}\n";
const std::string kOptions = "-D SCALE=2.0f -D OFFSET=1.0f";

// Runs `affine` over 16 items and checks x[i] == i * scale + offset.
void check_runs(const DeviceContext& device, const cl::Program& program, float scale,
                float offset) {
    cl::Kernel kernel = make_kernel(program, "affine");
    cl_int status = CL_SUCCESS;
    const size_t n = 16;
    cl::Buffer x(device.context, CL_MEM_WRITE_ONLY, n * sizeof(cl_float), nullptr, &status);
    REQUIRE(status == CL_SUCCESS);
    CL_CHECK(kernel.setArg(0, x));
    CL_CHECK(device.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(n)));
    std::vector<cl_float> got(n);
    CL_CHECK(device.queue.enqueueReadBuffer(x, CL_TRUE, 0, n * sizeof(cl_float), got.data()));
    for (size_t i = 0; i < n; ++i) CHECK(got[i] == float(i) * scale + offset);
}

cl::Program build(const DeviceContext& device, const std::string& source,
                  const std::string& options, BuildReport& report) {
    return build_program_cached(device.context, device.info.device, device.info, source, options,
                                &report);
}

std::vector<char> read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<char>((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::vector<char>& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

// A PoCL binary of layout version 9 (cl/pocl_binary.cpp) with one kernel record: program.bc
// holds `bc` bytes.
std::vector<unsigned char> synthetic_pocl_binary(size_t bc) {
    std::vector<unsigned char> b;
    auto u32 = [&](uint32_t v) {
        for (int i = 0; i < 4; ++i) b.push_back((unsigned char)(v >> (8 * i)));
    };
    auto u64 = [&](uint64_t v) {
        for (int i = 0; i < 8; ++i) b.push_back((unsigned char)(v >> (8 * i)));
    };
    const std::string magic("poclbin\0", 8), path = "/program.bc";
    b.insert(b.end(), magic.begin(), magic.end());
    u64(0x1234);                 // device id
    u32(9);                      // version
    u32(1);                      // kernels
    u64(0);                      // flags
    u32(1);                      // root entries
    b.insert(b.end(), 41, 'a');  // build hash
    u64(bc == 0 ? 0 : 4 + path.size() + 4 + bc);
    if (bc > 0) {
        u32(uint32_t(path.size()));
        b.insert(b.end(), path.begin(), path.end());
        u32(uint32_t(bc));
        b.insert(b.end(), bc, 0x42);
    }
    u64(8 + 24);  // the kernel record, its size field included
    b.insert(b.end(), 24, 0x17);
    return b;
}

// `binary`, a PoCL binary of version 9, with its program.bc entry emptied, as PoCL serialises
// it while another process has removed the file to rewrite it.
std::vector<unsigned char> without_program_bc(std::vector<unsigned char> binary) {
    const size_t at = 8 + 8 + 4 + 4 + 8 + 4 + 41;  // the first root entry's size
    uint64_t size = 0;
    for (int i = 7; i >= 0; --i) size = (size << 8) | binary.at(at + size_t(i));
    binary.erase(binary.begin() + long(at + 8), binary.begin() + long(at + 8 + size));
    for (size_t i = 0; i < 8; ++i) binary[at + i] = 0;
    return binary;
}

}  // namespace

namespace {
// The render program's options for the default settings.
std::string default_render_options() {
    return mcrt::variant_program_options(mcrt::resolve_variants(mcrt::RenderSettings{}), false,
                                         false);
}
}  // namespace

TEST_CASE("the cache directory follows MCRT_CACHE_DIR, XDG_CACHE_HOME, then HOME", "[cache]") {
    ScopedEnv env;
    env.unset("MCRT_NO_KERNEL_CACHE");
    env.set("MCRT_CACHE_DIR", "/tmp/a");
    env.set("XDG_CACHE_HOME", "/tmp/xdg");
    env.set("HOME", "/tmp/home");
    CHECK(binary_cache_directory() == "/tmp/a");
    env.unset("MCRT_CACHE_DIR");
    CHECK(binary_cache_directory() == "/tmp/xdg/mcrt/kernels");
    env.unset("XDG_CACHE_HOME");
    CHECK(binary_cache_directory() == "/tmp/home/.cache/mcrt/kernels");
    env.set("MCRT_NO_KERNEL_CACHE", "1");
    CHECK(binary_cache_directory().empty());
}

TEST_CASE("the key covers device, driver, source, options; its file name is hex", "[cache]") {
    DeviceInfo info;
    info.platform_name = "P";
    info.name = "D";
    info.version = "OpenCL 1.2";
    info.driver_version = "1.0";
    BinaryCacheKey key = binary_cache_key(info, kSource, kOptions);
    CHECK(key == binary_cache_key(info, kSource, kOptions));
    CHECK(key.hex().size() == 32);
    CHECK(key.hex().find_first_not_of("0123456789abcdef") == std::string::npos);
    CHECK(key != binary_cache_key(info, kSource + " ", kOptions));
    CHECK(key != binary_cache_key(info, kSource, kOptions + " "));
    // Moving text from one field to the next changes the key (fields are length-prefixed).
    CHECK(binary_cache_key(info, "ab", "c") != binary_cache_key(info, "a", "bc"));
    for (std::string DeviceInfo::*field : {&DeviceInfo::platform_name, &DeviceInfo::name,
                                           &DeviceInfo::version, &DeviceInfo::driver_version}) {
        DeviceInfo other = info;
        other.*field += "x";
        CHECK(key != binary_cache_key(other, kSource, kOptions));
    }
}

TEST_CASE("the key covers the vendor compiler's settings in the environment", "[cache]") {
    // Intel's CPU runtime builds other code under CL_CONFIG_USE_VECTORIZER=False: a binary
    // cached under one setting must not be read under the other.
    DeviceInfo info;
    info.platform_name = "Intel(R) OpenCL";
    ScopedEnv env;
    env.unset("CL_CONFIG_USE_VECTORIZER");
    BinaryCacheKey plain = binary_cache_key(info, kSource, kOptions);
    env.set("CL_CONFIG_USE_VECTORIZER", "False");
    BinaryCacheKey off = binary_cache_key(info, kSource, kOptions);
    CHECK(off != plain);
    env.set("CL_CONFIG_USE_VECTORIZER", "True");
    CHECK(binary_cache_key(info, kSource, kOptions) != off);
    env.unset("CL_CONFIG_USE_VECTORIZER");
    CHECK(binary_cache_key(info, kSource, kOptions) == plain);
    // Other variables do not change it.
    env.set("MCRT_UNRELATED_SETTING", "1");
    CHECK(binary_cache_key(info, kSource, kOptions) == plain);
}

TEST_CASE("a first build writes one entry, the second is a hit", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    BuildReport first, second;
    cl::Program a = build(device, kSource, kOptions, first);
    CHECK_FALSE(first.cache_hit);
    CHECK(first.store_error.empty());
    CHECK(first.rejected.empty());
    REQUIRE(cache.files().size() == 1);
    CHECK(cache.files()[0] == fs::path(first.path));
    CHECK(fs::path(first.path).extension() == ".bin");
    check_runs(device, a, 2.0f, 1.0f);

    cl::Program b = build(device, kSource, kOptions, second);
    CHECK(second.cache_hit);
    CHECK(second.path == first.path);
    CHECK(cache.files().size() == 1);
    check_runs(device, b, 2.0f, 1.0f);

    std::vector<char> bytes = read_bytes(first.path);
    REQUIRE(bytes.size() > 40);
    CHECK(std::string(bytes.data(), 8) == "MCRTBIN1");
}

TEST_CASE("with store_after_misses 3 the third miss stores the binary, the fourth build hits",
          "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    for (int build_number = 1; build_number <= 4; ++build_number) {
        INFO("build " << build_number);
        BuildReport report;
        cl::Program program = build_program_cached(device.context, device.info.device, device.info,
                                                   kSource, kOptions, &report, 3);
        check_runs(device, program, 2.0f, 1.0f);
        const bool stored = fs::exists(report.path);
        CHECK(report.cache_hit == (build_number == 4));
        CHECK(report.store_deferred == (build_number <= 2));
        CHECK(stored == (build_number >= 3));
        // The miss counter beside the entry, gone once the binary is stored.
        fs::path counter = fs::path(report.path).replace_extension(".misses");
        CHECK(fs::exists(counter) == (build_number <= 2));
        CHECK(cache.files().size() == 1);
    }
}

TEST_CASE("other options or another source give another entry", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    BuildReport r1, r2, r3, r4;
    build(device, kSource, kOptions, r1);
    cl::Program p2 = build(device, kSource, "-D SCALE=3.0f -D OFFSET=-1.0f", r2);
    cl::Program p3 = build(device, "// another source\n" + kSource, kOptions, r3);
    CHECK_FALSE(r2.cache_hit);
    CHECK_FALSE(r3.cache_hit);
    CHECK(r1.path != r2.path);
    CHECK(r1.path != r3.path);
    CHECK(r2.path != r3.path);
    CHECK(cache.files().size() == 3);
    check_runs(device, p2, 3.0f, -1.0f);
    check_runs(device, p3, 2.0f, 1.0f);

    // Each is then a hit on its own entry, with its own options' result.
    cl::Program p4 = build(device, kSource, "-D SCALE=3.0f -D OFFSET=-1.0f", r4);
    CHECK(r4.cache_hit);
    CHECK(r4.path == r2.path);
    check_runs(device, p4, 3.0f, -1.0f);
}

TEST_CASE("a corrupt entry is rebuilt from source and replaced", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    BuildReport first;
    build(device, kSource, kOptions, first);
    const std::vector<char> valid = read_bytes(first.path);
    REQUIRE(valid.size() > 64);

    // Each corruption, then a build: not a hit, the entry is valid again and the program runs.
    auto corrupted = [&](std::vector<char> bytes) {
        write_bytes(first.path, bytes);
        BuildReport rebuilt, again;
        cl::Program program = build(device, kSource, kOptions, rebuilt);
        CHECK_FALSE(rebuilt.cache_hit);
        CHECK_FALSE(rebuilt.rejected.empty());
        CHECK(rebuilt.store_error.empty());
        check_runs(device, program, 2.0f, 1.0f);
        CHECK(cache.files().size() == 1);
        cl::Program reloaded = build(device, kSource, kOptions, again);
        CHECK(again.cache_hit);
        check_runs(device, reloaded, 2.0f, 1.0f);
        return rebuilt.rejected;
    };

    SECTION("truncated payload") {
        std::vector<char> bytes(valid.begin(), valid.begin() + valid.size() / 2);
        CHECK_THAT(corrupted(bytes), Catch::StartsWith("payload size"));
    }
    SECTION("truncated header") {
        std::vector<char> bytes(valid.begin(), valid.begin() + 20);
        CHECK(corrupted(bytes) == "truncated header");
    }
    SECTION("empty file") { CHECK(corrupted({}) == "truncated header"); }
    SECTION("flipped payload bytes") {
        std::vector<char> bytes = valid;
        for (size_t i = 40; i < bytes.size(); i += 97) bytes[i] = char(bytes[i] ^ 0x5a);
        CHECK(corrupted(bytes) == "payload hash mismatch");
    }
    SECTION("wrong magic") {
        std::vector<char> bytes = valid;
        bytes[7] = '9';
        CHECK(corrupted(bytes) == "wrong magic");
    }
    SECTION("another key's entry under this name") {
        std::vector<char> bytes = valid;
        bytes[8] = char(bytes[8] ^ 1);
        CHECK(corrupted(bytes) == "wrong key");
    }
    SECTION("a well-formed entry whose binary the driver rejects") {
        BinaryCacheKey key = binary_cache_key(device.info, kSource, kOptions);
        std::vector<unsigned char> garbage(4096);
        for (size_t i = 0; i < garbage.size(); ++i) garbage[i] = (unsigned char)(i * 131 + 7);
        REQUIRE(store_binary_cache_entry(first.path, key, garbage).empty());
        // PoCL refuses it at clCreateProgramWithBinary (CL_INVALID_BINARY), others may at build.
        CHECK_THAT(corrupted(read_bytes(first.path)), Catch::StartsWith("cl"));
    }
    SECTION("a PoCL binary without program.bc, never handed to the driver") {
        // PoCL serialises such a binary while another process rewrites its cache, and aborts the
        // process when asked to build it (pocl_binary_get_kernels_metadata: `len > 0').
        const std::vector<unsigned char> payload(valid.begin() + 40, valid.end());
        const bool pocl =
            pocl_binary_problem(payload).empty() &&
            std::string(valid.begin() + 40, valid.begin() + 48) == std::string("poclbin\0", 8);
        const std::vector<unsigned char> broken =
            pocl ? without_program_bc(payload) : synthetic_pocl_binary(0);
        BinaryCacheKey key = binary_cache_key(device.info, kSource, kOptions);
        REQUIRE(store_binary_cache_entry(first.path, key, broken).empty());
        CHECK_THAT(corrupted(read_bytes(first.path)), Catch::Contains("program.bc"));
    }
}

TEST_CASE("a PoCL binary is whole only with program.bc and kernel records that fit", "[cache]") {
    CHECK(pocl_binary_problem(synthetic_pocl_binary(16)).empty());
    CHECK_THAT(pocl_binary_problem(synthetic_pocl_binary(0)),
               Catch::Contains("root entry 0 (program.bc) is empty"));
    std::vector<unsigned char> cut = synthetic_pocl_binary(16);
    cut.resize(cut.size() - 1);
    CHECK_THAT(pocl_binary_problem(cut), Catch::Contains("kernel record 0 has size 32"));
    std::vector<unsigned char> longer = synthetic_pocl_binary(16);
    longer.push_back(0);
    CHECK_THAT(pocl_binary_problem(longer), Catch::Contains("1 bytes after the last kernel"));
    std::vector<unsigned char> no_bytes = synthetic_pocl_binary(16);
    no_bytes.resize(77 + 8 + 4 + 11 + 4);  // the file's content cut off
    CHECK_THAT(pocl_binary_problem(no_bytes), Catch::Contains("runs past"));
    // Not judged: another driver's binary, and a PoCL layout this check does not know.
    CHECK(pocl_binary_problem({}).empty());
    CHECK(pocl_binary_problem(std::vector<unsigned char>(100, 0x7f)).empty());
    std::vector<unsigned char> newer = synthetic_pocl_binary(0);
    newer[16] = 10;
    CHECK(pocl_binary_problem(newer).empty());
}

TEST_CASE("the device's own binary of a program passes the PoCL check", "[cache]") {
    // Guards the layout read by pocl_binary_problem against the installed PoCL: a misread would
    // refuse every binary and so store none.
    DeviceContext device = first_device();
    cl::Program program = build_program(device.context, device.info.device, kSource, kOptions);
    const std::vector<unsigned char> binary = program_binary(program, device.info.device);
    REQUIRE_FALSE(binary.empty());
    CHECK(pocl_binary_problem(binary).empty());
    if (device.info.platform_name.find("Portable Computing Language") != std::string::npos) {
        REQUIRE(std::string(binary.begin(), binary.begin() + 8) == std::string("poclbin\0", 8));
        CHECK_THAT(pocl_binary_problem(without_program_bc(binary)),
                   Catch::Contains("(program.bc) is empty"));
    }
}

TEST_CASE("an unwritable cache directory does not fail the build", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    BuildReport report;

    SECTION("read-only directory") {
        fs::create_directories(cache.dir);
        fs::permissions(cache.dir, fs::perms::owner_read | fs::perms::owner_exec);
        cl::Program program = build(device, kSource, kOptions, report);
        check_runs(device, program, 2.0f, 1.0f);
        CHECK_FALSE(report.cache_hit);
        // root writes anyway; anyone else is refused, and told so in the report.
        if (::geteuid() != 0) {
            CHECK(cache.files().empty());
            CHECK_FALSE(report.store_error.empty());
        }
    }
    SECTION("a file where the directory should be") {
        fs::create_directories(cache.dir);
        std::ofstream(cache.dir / "not-a-directory") << "x";
        cache.env.set("MCRT_CACHE_DIR", (cache.dir / "not-a-directory" / "kernels").string());
        cl::Program program = build(device, kSource, kOptions, report);
        check_runs(device, program, 2.0f, 1.0f);
        CHECK_FALSE(report.cache_hit);
        CHECK_FALSE(report.store_error.empty());
        CHECK(cache.files().size() == 1);  // only the plain file
    }
}

TEST_CASE("the cache creates its directory tree", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    fs::path nested = cache.dir / "a" / "b" / "kernels";
    cache.env.set("MCRT_CACHE_DIR", nested.string());
    BuildReport report;
    build(device, kSource, kOptions, report);
    CHECK(report.store_error.empty());
    CHECK(fs::exists(report.path));
    CHECK(fs::path(report.path).parent_path() == nested);
}

TEST_CASE("MCRT_NO_KERNEL_CACHE=1 builds from source and writes nothing", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    cache.env.set("MCRT_NO_KERNEL_CACHE", "1");
    BuildReport first, second;
    cl::Program a = build(device, kSource, kOptions, first);
    cl::Program b = build(device, kSource, kOptions, second);
    CHECK_FALSE(first.cache_hit);
    CHECK_FALSE(second.cache_hit);
    CHECK(second.path.empty());
    CHECK_FALSE(fs::exists(cache.dir));
    check_runs(device, b, 2.0f, 1.0f);
}

TEST_CASE("a broken source still throws with the build log, and is not cached", "[cache]") {
    DeviceContext device = first_device();
    TempCache cache;
    std::string source =
        "#line 1 \"broken.cl\"\nkernel void k(global float* x) {\n"
        "    x[0] = undefined_name;\n}\n";
    for (int attempt = 0; attempt < 2; ++attempt) {
        try {
            BuildReport report;
            build(device, source, "", report);
            FAIL("the broken kernel built");
        } catch (const RuntimeError& e) {
            std::string what = e.what();
            CHECK(what.find("kernel build failed") != std::string::npos);
            CHECK(what.find("undefined_name") != std::string::npos);
            CHECK(what.find("broken.cl:2") != std::string::npos);
        }
    }
    CHECK(cache.files().empty());
}

TEST_CASE("cached_program stores the render kernel in the binary cache", "[cache]") {
    // On PoCL, cached_program stores a variant's binary at its third build only, unless PoCL's
    // own cache is off (then at once).
    setenv("POCL_KERNEL_CACHE", "0", 1);
    DeviceContext device = first_device();
    TempCache cache;
    cl::Program program = cached_program(device, "render.cl", default_render_options());
    unsetenv("POCL_KERNEL_CACHE");
    CHECK(program());
    CHECK(cache.files().size() == 1);
    BuildReport report;
    // cached_program adds the device's own options (device_program_options) to the key.
    build(device, kernel_source("render.cl"),
          default_render_options() + device_program_options(device.info), report);
    CHECK(report.cache_hit);
}

// The cache directory is the user's, but what lies in it may be planted: a link, a FIFO or a
// directory named like an entry. The cache never writes through a link, never blocks on a FIFO,
// and heals itself by removing what is not a regular file (a link's target stays untouched).
TEST_CASE("the cache never follows, blocks on or keeps what is planted at an entry's name",
          "[cache][hostile]") {
    DeviceContext device = first_device();
    TempCache cache;
    fs::create_directories(cache.dir);
    const fs::path victim_dir =
        cache.dir.parent_path() / (cache.dir.filename().string() + "-victim");
    fs::create_directories(victim_dir);
    struct RemoveVictims {
        fs::path dir;
        ~RemoveVictims() {
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    } remove_victims{victim_dir};
    const fs::path victim = victim_dir / "precious.txt";
    std::ofstream(victim) << "precious";
    const std::string key = binary_cache_key(device.info, kSource, kOptions).hex();
    const fs::path entry = cache.dir / (key + ".bin"), counter = cache.dir / (key + ".misses");

    // Builds, then checks the entry is a regular file that hits.
    auto build_and_heal = [&](int store_after_misses) {
        BuildReport report;
        cl::Program program = build_program_cached(device.context, device.info.device, device.info,
                                                   kSource, kOptions, &report, store_after_misses);
        check_runs(device, program, 2.0f, 1.0f);
        CHECK_FALSE(report.cache_hit);
        return report;
    };
    auto entry_hits = [&] {
        CHECK(fs::symlink_status(entry).type() == fs::file_type::regular);
        BuildReport again;
        build(device, kSource, kOptions, again);
        CHECK(again.cache_hit);
    };

    SECTION("a link to a file") {
        fs::create_symlink(victim, entry);
        const BuildReport r = build_and_heal(1);
        CHECK_THAT(r.rejected, Catch::Contains("symbolic link"));
        CHECK(r.store_error.empty());
        entry_hits();
    }
    SECTION("a dangling link") {
        const fs::path elsewhere = victim_dir / "created.bin";
        fs::create_symlink(elsewhere, entry);
        build_and_heal(1);
        CHECK_FALSE(fs::exists(elsewhere));
        entry_hits();
    }
    SECTION("a link at the miss counter") {
        std::ofstream(victim, std::ios::trunc) << "7\n";
        fs::create_symlink(victim, counter);
        const BuildReport r = build_and_heal(3);
        CHECK(r.store_deferred);
        CHECK(fs::symlink_status(counter).type() == fs::file_type::regular);
        CHECK(read_bytes(counter) == std::vector<char>{'1', '\n'});  // the link's 7 not read
        std::ofstream(victim, std::ios::trunc) << "precious";
    }
    SECTION("a FIFO") {
        REQUIRE(::mkfifo(entry.c_str(), 0644) == 0);
        const BuildReport r = build_and_heal(1);  // open(2) on a FIFO would block forever
        CHECK_THAT(r.rejected, Catch::Contains("FIFO"));
        entry_hits();
    }
    SECTION("an empty directory") {
        fs::create_directory(entry);
        const BuildReport r = build_and_heal(1);
        CHECK_THAT(r.rejected, Catch::Contains("directory"));
        CHECK(r.store_error.empty());
        entry_hits();
    }
    SECTION("a directory with files: the build works and the report says why nothing is stored") {
        fs::create_directory(entry);
        std::ofstream(entry / "user-file") << "mine";
        const BuildReport r = build_and_heal(1);
        CHECK_THAT(r.store_error, Catch::Contains("not empty"));
        CHECK(read_bytes(entry / "user-file") == std::vector<char>{'m', 'i', 'n', 'e'});
    }
    CHECK(read_bytes(victim) == std::vector<char>{'p', 'r', 'e', 'c', 'i', 'o', 'u', 's'});
    CHECK(fs::symlink_status(victim).type() == fs::file_type::regular);
    for (const fs::path& file : cache.files())
        CHECK(file.filename().string().find(".tmp-") == std::string::npos);
}

TEST_CASE("a stale temporary of a killed writer is swept from the cache directory",
          "[cache][hostile]") {
    DeviceContext device = first_device();
    TempCache cache;
    fs::create_directories(cache.dir);
    const std::string key = binary_cache_key(device.info, kSource, kOptions).hex();
    // A PID that names no process: a child that has exited and been reaped.
    const pid_t dead = ::fork();
    if (dead == 0) ::_exit(0);
    int status = 0;
    REQUIRE(::waitpid(dead, &status, 0) == dead);
    const fs::path stale = cache.dir / ("." + key + ".bin.tmp-" + std::to_string(dead) + "-0");
    std::ofstream(stale) << "half a binary";
    BuildReport report;
    build(device, kSource, kOptions, report);
    CHECK(report.store_error.empty());
    CHECK_FALSE(fs::exists(stale));
    CHECK(cache.files().size() == 1);
}

TEST_CASE("mcrt build-program run by hand replaces nothing and says why", "[cache][hostile]") {
    const fs::path dir =
        fs::temp_directory_path() / ("mcrt-user-dir-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / "binary") << "the user's";
    std::ofstream(dir / "error") << "also the user's";
    std::ofstream(dir / "source.cl") << kSource;
    std::ofstream(dir / "options") << kOptions;
    auto run = [](const std::string& arguments) {
        const std::string command =
            "'" + std::string(MCRT_EXE) + "' build-program " + arguments + " 2>&1";
        std::string out;
        FILE* pipe = ::popen(command.c_str(), "r");
        REQUIRE(pipe != nullptr);
        char buffer[512];
        while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
        const int status = ::pclose(pipe);
        return std::make_pair(WIFEXITED(status) ? WEXITSTATUS(status) : -1, out);
    };
    SECTION("a directory of the user's") {
        const auto [code, out] = run("'" + dir.string() + "' 0");
        CHECK(code == 2);
        CHECK_THAT(out, Catch::StartsWith("mcrt: error: build-program: " + dir.string()));
        CHECK_THAT(out, Catch::Contains("not a kernel build directory"));
    }
    SECTION("a missing directory") {
        const auto [code, out] = run("'" + (dir / "missing").string() + "' 0");
        CHECK(code == 2);
        CHECK_THAT(out, Catch::Contains("No such file or directory"));
    }
    CHECK(read_bytes(dir / "binary") ==
          std::vector<char>{'t', 'h', 'e', ' ', 'u', 's', 'e', 'r', '\'', 's'});
    CHECK(read_bytes(dir / "error").size() == 15);
    std::error_code ec;
    fs::remove_all(dir, ec);
}

TEST_CASE("a build directory left by a killed render is removed by the next child build",
          "[cache][hostile]") {
    const pid_t dead = ::fork();
    if (dead == 0) ::_exit(0);
    int status = 0;
    REQUIRE(::waitpid(dead, &status, 0) == dead);
    const fs::path stale =
        fs::temp_directory_path() / ("mcrt-build-" + std::to_string(dead) + "-a1B2c3");
    fs::create_directories(stale);
    std::ofstream(stale / "source.cl") << kSource;
    // A directory of a live process (this one) under the same pattern stays.
    const fs::path alive =
        fs::temp_directory_path() / ("mcrt-build-" + std::to_string(::getpid()) + "-zZ9yY8");
    fs::create_directories(alive);
    DeviceContext device = first_device();
    const std::vector<unsigned char> binary = build_binary_in_child(device.info, kSource, kOptions);
    CHECK_FALSE(binary.empty());
    CHECK_FALSE(fs::exists(stale));
    CHECK(fs::exists(alive));
    std::error_code ec;
    fs::remove_all(alive, ec);
}
