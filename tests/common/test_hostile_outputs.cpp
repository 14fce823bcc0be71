// Outputs that destroy, signals and pipes, images too large (docs/ROBUSTNESS.md, "Hostile input"):
// no output path is replaced unless it is a regular file that is no other output and no input, no
// temporary file survives any way the process can end, and a closed stderr pipe or a late
// SIGTERM does not lose the image. The tests never point an output at a system file: FIFOs,
// directories and devices are made in a temporary directory (mkfifo needs no privilege).
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/output_paths.h"
#include "hostile_support.h"
#include "image/image.h"
#include "process_support.h"
#include "render/memory_estimate.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

std::vector<std::string> small_render(const std::string& out) {
    return {"render", kCornell, "--width", "16",    "--height", "12",
            "--spp",  "16",     "--quiet", "--out", out};
}

std::vector<std::string> with(std::vector<std::string> args,
                              std::initializer_list<std::string> more) {
    args.insert(args.end(), more);
    return args;
}

// Every name in `dir`, hidden ones included.
std::vector<std::string> names_in(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

void write_text(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// A file's bytes and inode: "unchanged" means both.
struct FileState {
    std::string bytes;
    ino_t inode = 0;
    bool operator==(const FileState& o) const { return bytes == o.bytes && inode == o.inode; }
};

FileState state_of(const fs::path& path) {
    struct stat st {};
    REQUIRE(::stat(path.c_str(), &st) == 0);
    return {read_whole_file(path), st.st_ino};
}

// The string header attribute `name` of the EXR at `path`.
std::string exr_attribute(const std::string& path, const std::string& name) {
    Imf::InputFile file(path.c_str());
    const auto* value = file.header().findTypedAttribute<Imf::StringAttribute>(name);
    return value ? value->value() : std::string();
}

void require_one_error(const ProcessResult& r, int status, const std::string& needle) {
    INFO("stderr: " << r.err);
    REQUIRE_FALSE(r.timed_out);
    CHECK(r.exit_code == status);
    CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
    CHECK(r.err.find(needle) != std::string::npos);
}

}  // namespace

TEST_CASE("an existing output that is not a regular file is refused before rendering",
          "[outputs][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    const std::string fifo = dir / "fifo", directory = dir / "directory";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    fs::create_directory(directory);
    for (const std::string option : {"--out", "--png", "--stats"}) {
        for (const std::string& target : {fifo, directory}) {
            DYNAMIC_SECTION(option << " " << fs::path(target).filename().string()) {
                std::vector<std::string> args =
                    small_render(option == "--out" ? target : dir / "a.exr");
                if (option != "--out") args = with(args, {option, target});
                const ProcessResult r = run_process(MCRT_EXE, args, logs.path(), 60);
                require_one_error(r, 2, "refusing to replace it");
                struct stat st {};
                REQUIRE(::stat(fifo.c_str(), &st) == 0);
                CHECK(S_ISFIFO(st.st_mode));
                CHECK(fs::is_directory(directory));
                CHECK_FALSE(fs::exists(dir / "a.exr"));
            }
        }
    }
}

TEST_CASE("write_atomically never replaces what is not a regular file", "[outputs][hostile]") {
    TempDir dir("mcrt-hostile");
    const std::string fifo = dir / "fifo";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    CHECK_THROWS_AS(write_atomically(fifo, [](const std::string& t) { write_text(t, "x"); }),
                    InputError);
    struct stat st {};
    REQUIRE(::stat(fifo.c_str(), &st) == 0);
    CHECK(S_ISFIFO(st.st_mode));
    CHECK(names_in(dir.path()) == std::vector<std::string>{"fifo"});
}

TEST_CASE("two outputs that are the same file are refused", "[outputs][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    const std::string exr = dir / "a.exr";
    SECTION("the same name") {
        const ProcessResult r =
            run_process(MCRT_EXE, with(small_render(exr), {"--png", exr}), logs.path(), 60);
        require_one_error(r, 2, "the same file as --out");
        CHECK_FALSE(fs::exists(exr));
    }
    SECTION("the same name written differently") {
        const ProcessResult r = run_process(
            MCRT_EXE, with(small_render(exr), {"--stats", dir.path().string() + "/./a.exr"}),
            logs.path(), 60);
        require_one_error(r, 2, "the same file as --out");
    }
    SECTION("a hard link and a symbolic link to an existing output") {
        write_text(exr, "precious");
        fs::create_hard_link(exr, dir / "hard.json");
        fs::create_symlink(exr, dir / "soft.png");
        for (const auto& [option, other] : std::vector<std::pair<std::string, std::string>>{
                 {"--stats", dir / "hard.json"}, {"--png", dir / "soft.png"}}) {
            const ProcessResult r =
                run_process(MCRT_EXE, with(small_render(exr), {option, other}), logs.path(), 60);
            require_one_error(r, 2, "the same file as --out");
            CHECK(read_whole_file(exr) == "precious");
        }
    }
}

TEST_CASE("an output that is an input (the scene or its buffer) is refused", "[outputs][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    const fs::path source = fs::path(kCornell).parent_path();
    fs::copy_file(kCornell, dir / "box.gltf");
    // The .gltf names its buffer: copy it under the same name.
    fs::copy_file(source / "CornellBox-Original.bin", dir / "CornellBox-Original.bin");
    const std::string scene = read_whole_file(dir / "box.gltf");
    const std::string buffer = read_whole_file(dir / "CornellBox-Original.bin");
    auto args = [&](const std::string& out) {
        return std::vector<std::string>{
            "render", dir / "box.gltf", "--width", "8", "--height", "8", "--spp",
            "16",     "--quiet",        "--out",   out};
    };
    require_one_error(run_process(MCRT_EXE, args(dir / "box.gltf"), logs.path(), 60), 2,
                      "is the input");
    require_one_error(
        run_process(MCRT_EXE, with(args(dir / "a.exr"), {"--png", dir / "CornellBox-Original.bin"}),
                    logs.path(), 60),
        2, "is the input");
    CHECK(read_whole_file(dir / "box.gltf") == scene);
    CHECK(read_whole_file(dir / "CornellBox-Original.bin") == buffer);
    CHECK_FALSE(fs::exists(dir / "a.exr"));
}

TEST_CASE("a write that fails names the reason, exits 1 and leaves no temporary file",
          "[outputs][hostile]") {
    // A file-size limit set on mcrt just before it writes (the kernel build needs files of its
    // own) fails the EXR's write(2) as a full disk does: mcrt ignores SIGXFSZ, so the write
    // returns EFBIG and its reason is named.
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    for (const std::string tmpfile : {"", "MCRT_TEST_NO_TMPFILE=1"}) {
        DYNAMIC_SECTION("temporary " << (tmpfile.empty() ? "unnamed" : "named")) {
            std::vector<std::string> args = {MCRT_EXE,  "render",      kCornell, "--width",
                                             "64",      "--height",    "48",     "--spp",
                                             "16",      "--quiet",     "--out",  dir / "a.exr",
                                             "--stats", dir / "a.json"};
            write_text(dir / "a.json", "old stats");
            std::vector<std::string> env = {"MCRT_TEST_PAUSE=before-write",
                                            "MCRT_TEST_PAUSE_UNTIL=" + (logs / "go")};
            if (!tmpfile.empty()) env.push_back(tmpfile);
            std::filesystem::remove(logs / "go");
            Child child(args, env, logs / "log");
            REQUIRE(child.wait_for_text("paused at before-write", 60));
            const struct rlimit limit = {4096, 4096};
            REQUIRE(::prlimit(child.render_pid(), RLIMIT_FSIZE, &limit, nullptr) == 0);
            write_text(logs / "go", "");
            const int status = child.wait(60);
            const std::string err = child.output();
            INFO(err);
            REQUIRE(WIFEXITED(status));
            CHECK(WEXITSTATUS(status) == 1);
            CHECK(lines_starting_with(err, "mcrt: error:").size() == 1);
            CHECK(err.find("File too large") != std::string::npos);
            CHECK(names_in(dir.path()) == std::vector<std::string>{"a.json"});
            CHECK(read_whole_file(dir / "a.json") == "old stats");
            fs::remove(dir / "a.json");
        }
    }
}

TEST_CASE("SIGKILL while an output is written leaves no temporary file",
          "[outputs][signals][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    const std::string exr = dir / "a.exr";
    std::vector<std::string> args = small_render(exr);
    args.insert(args.begin(), MCRT_EXE);
    {
        Child child(args, {"MCRT_TEST_PAUSE=write"}, logs / "log1");
        REQUIRE(child.wait_for_text("paused at write", 60));
        child.signal(SIGKILL);
        const int status = child.wait(30);
        CHECK(WIFSIGNALED(status));
        CHECK(names_in(dir.path()).empty());
    }
    SECTION("named temporary: the next write sweeps the dead process's file") {
        Child child(args, {"MCRT_TEST_PAUSE=write", "MCRT_TEST_NO_TMPFILE=1"}, logs / "log2");
        REQUIRE(child.wait_for_text("paused at write", 60));
        child.signal(SIGKILL);
        child.wait(30);
        const std::vector<std::string> left = names_in(dir.path());
        REQUIRE(left.size() == 1);
        CHECK(left[0].rfind(".a.exr.tmp-", 0) == 0);
        const ProcessResult r = run_process(MCRT_EXE, small_render(exr), logs.path(), 60);
        CHECK(r.exit_code == 0);
        CHECK(names_in(dir.path()) == std::vector<std::string>{"a.exr"});
    }
}

TEST_CASE("a second SIGINT while an output is written leaves no temporary file",
          "[outputs][signals][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    std::vector<std::string> args = with(small_render(dir / "a.exr"), {"--stats", dir / "a.json"});
    args.insert(args.begin(), MCRT_EXE);
    Child child(args, {"MCRT_TEST_PAUSE=write"}, logs / "log");
    REQUIRE(child.wait_for_text("paused at write", 60));
    child.signal(SIGINT);  // asks to stop: the render is done, writing goes on
    REQUIRE(child.wait_handler_reset(SIGINT, 30));
    child.signal(SIGINT);  // the second one ends the process at once (SA_RESETHAND)
    const int status = child.wait(30);
    INFO(child.output());
    CHECK(WIFSIGNALED(status));
    CHECK(names_in(dir.path()).empty());
}

TEST_CASE("a closed stderr pipe does not kill mcrt: the image is still written",
          "[signals][hostile]") {
    // `mcrt render … 2>&1 | head -c 10` with head gone.
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    std::vector<std::string> args = {MCRT_EXE, "render",   kCornell,     "--width",
                                     "16",     "--height", "12",         "--spp",
                                     "16",     "--out",    dir / "a.exr"};
    Child child(args, {}, logs / "log", true);
    const int status = child.wait(60);
    REQUIRE_FALSE(child.timed_out());
    CHECK_FALSE(WIFSIGNALED(status));
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    const Image img = read_exr(dir / "a.exr");
    CHECK(img.width == 16);
}

TEST_CASE("SIGTERM after the outputs are complete exits 0", "[signals][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    std::vector<std::string> args = small_render(dir / "a.exr");
    args.insert(args.begin(), MCRT_EXE);
    Child child(args, {"MCRT_TEST_PAUSE=exit", "MCRT_TEST_PAUSE_SECONDS=2"}, logs / "log");
    REQUIRE(child.wait_for_text("paused at exit", 60));
    child.signal(SIGTERM);
    child.signal(SIGINT);
    const int status = child.wait(30);
    INFO(child.output());
    CHECK_FALSE(WIFSIGNALED(status));
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    CHECK(read_exr(dir / "a.exr").width == 16);
}

TEST_CASE("error messages name the real cause", "[cli][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    SECTION("an unknown subcommand names itself") {
        const ProcessResult r = run_process(MCRT_EXE, {"frobnicate"}, logs.path(), 30);
        require_one_error(r, 2, "unknown subcommand 'frobnicate'");
    }
    SECTION("an unusable PoCL cache directory is not 'no device'") {
        write_text(dir / "file", "x");
        std::string command =
            "POCL_CACHE_DIR='" + (dir / "file") + "/pocl' exec '" + MCRT_EXE + "' devices";
        const ProcessResult r = run_process("/bin/sh", {"-c", command}, logs.path(), 30);
        if (r.exit_code == 0)
            skip_test("this OpenCL platform does not need PoCL's cache directory");
        require_one_error(r, 1, "kernel cache directory");
    }
}

TEST_CASE("an image too large for host memory is refused before rendering", "[memory][hostile]") {
    const uint64_t need = render_host_bytes(16384, 16384, 1);
    CHECK(need > uint64_t(16384) * 16384 * 120);  // accumulator doubles and image floats at least
    CHECK_THROWS_AS(check_host_memory("x", ~uint64_t(0) / 2), RuntimeError);
    CHECK_NOTHROW(check_host_memory("x", 1));
    const uint64_t available = available_host_bytes();
    if (available == 0 || available >= need) skip_test("this machine has room for a 16384² render");
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    const ProcessResult r = run_process(MCRT_EXE,
                                        {"render", kCornell, "--width", "16384", "--height",
                                         "16384", "--spp", "1", "--quiet", "--out", dir / "a.exr"},
                                        logs.path(), 60);
    require_one_error(r, 1, "of host memory");
    CHECK(names_in(dir.path()).empty());
    const ProcessResult b = run_process(
        MCRT_EXE, {"bench", kCornell, "--width", "16384", "--height", "16384", "--repeats", "1"},
        logs.path(), 60);
    require_one_error(b, 1, "memory");
}

TEST_CASE("an output through a symbolic link replaces the link's target and keeps the link",
          "[outputs][hostile][links]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    fs::create_directory(dir.path() / "real");
    struct Link {
        std::string name;                                        // the link the option names
        std::vector<std::pair<std::string, std::string>> chain;  // link → what it holds
        std::string target;  // the file that must receive the output
    };
    for (const std::string option : {"--out", "--png", "--stats"}) {
        const std::string ext = option == "--out" ? ".exr" : option == "--png" ? ".png" : ".json";
        const std::vector<Link> links = {
            {"absolute", {{"absolute" + ext, dir / ("real/abs" + ext)}}, "real/abs" + ext},
            {"relative", {{"relative" + ext, "real/rel" + ext}}, "real/rel" + ext},
            {"chain",
             {{"chain" + ext, "middle" + ext}, {"middle" + ext, "real/end" + ext}},
             "real/end" + ext},
            {"dangling", {{"dangling" + ext, "real/new" + ext}}, "real/new" + ext},
        };
        for (const Link& link : links) {
            DYNAMIC_SECTION(option << " through a " << link.name << " link") {
                for (const auto& [name, to] : link.chain) fs::create_symlink(to, dir / name);
                if (link.name != "dangling") write_text(dir / link.target, "old");
                const std::string named = dir / link.chain.front().first;
                std::vector<std::string> args =
                    small_render(option == "--out" ? named : dir / "a.exr");
                if (option != "--out") args = with(args, {option, named});
                const ProcessResult r = run_process(MCRT_EXE, args, logs.path(), 60);
                INFO(r.err);
                REQUIRE(r.exit_code == 0);
                for (const auto& [name, to] : link.chain) {
                    CHECK(fs::is_symlink(dir / name));
                    CHECK(fs::read_symlink(dir / name) == fs::path(to));
                }
                const std::string written = read_whole_file(dir / link.target);
                CHECK(written.size() > 100);
                if (option == "--stats")
                    CHECK(nlohmann::json::parse(written)["seed"] == 0);
                else if (option == "--out")
                    CHECK(read_exr(dir / link.target).width == 16);
                for (const fs::path& d : {dir.path(), dir.path() / "real"})
                    for (const std::string& name : names_in(d))
                        CHECK(name.find(".tmp-") == std::string::npos);
            }
        }
    }
}

TEST_CASE("integrate --out through a symbolic link replaces the target",
          "[outputs][hostile][links]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    write_text(dir / "real.csv", "old");
    fs::create_symlink("real.csv", dir / "link.csv");
    const ProcessResult r = run_process(
        MCRT_EXE, {"integrate", "--n", "16", "--repeats", "2", "--out", dir / "link.csv"},
        logs.path(), 60);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(fs::is_symlink(dir / "link.csv"));
    CHECK(read_whole_file(dir / "real.csv").rfind("estimator,n,", 0) == 0);
}

TEST_CASE("/dev/stdout as an output: a redirected file is written, a pipe is refused",
          "[outputs][hostile][links]") {
    // A link of the test's own, as /dev/stdout is one (to /proc/self/fd/1): a binary that
    // replaced the link instead of writing through it cannot touch the system's.
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    const fs::path link = dir / "stdout";
    fs::create_symlink("/proc/self/fd/1", link);
    const std::string command = "exec '" + std::string(MCRT_EXE) + "' render '" + kCornell +
                                "' --width 8 --height 8 --spp 16 --quiet --out '" +
                                (dir / "a.exr") + "' --stats '" + link.string() + "'";
    SECTION("stdout redirected to a file") {
        const ProcessResult r = run_process(
            "/bin/sh", {"-c", command + " > '" + (dir / "so.json") + "'"}, logs.path(), 60);
        INFO(r.err);
        REQUIRE(r.exit_code == 0);
        CHECK(nlohmann::json::parse(read_whole_file(dir / "so.json"))["width"] == 8);
    }
    SECTION("stdout a pipe") {
        const ProcessResult r = run_process("/bin/sh", {"-c", command + " | cat"}, logs.path(), 60);
        CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
        CHECK(r.err.find(link.string() + ": is a FIFO") != std::string::npos);
        CHECK_FALSE(fs::exists(dir / "a.exr"));
    }
    CHECK(fs::is_symlink(link));
    CHECK(fs::read_symlink(link) == "/proc/self/fd/1");
}

TEST_CASE("an output where no file can be created is refused before the scene is loaded",
          "[outputs][hostile]") {
    // The scene does not exist: an error about it would mean the outputs were checked after it.
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    write_text(dir / "file", "x");
    struct Case {
        std::string label, stats, reason;  // label: a section name that is the same every run
    };
    std::vector<Case> cases = {
        {"under /proc", "/proc/mcrt-test.json", "cannot create a file in /proc"},
        {"under a file", dir / "file/x.json", "file is not a directory"},
    };
    if (::geteuid() != 0) {  // root writes into a mode-555 directory regardless
        fs::create_directory(dir.path() / "readonly");
        fs::permissions(dir.path() / "readonly", fs::perms(0555));
        cases.push_back(
            {"in a read-only directory", dir / "readonly/x.json", "cannot create a file in"});
    }
    for (const Case& c : cases) {
        DYNAMIC_SECTION("--stats " << c.label) {
            const ProcessResult r = run_process(
                MCRT_EXE,
                {"render", dir / "no-scene.gltf", "--out", dir / "a.exr", "--stats", c.stats},
                logs.path(), 60);
            require_one_error(r, 2, "--stats " + c.stats + ": ");
            CHECK(r.err.find(c.reason) != std::string::npos);
            CHECK(r.err.find("no-scene.gltf") == std::string::npos);
            CHECK_FALSE(fs::exists(dir / "a.exr"));
        }
    }
}

TEST_CASE("the outputs of a render land together or not at all", "[outputs][hostile]") {
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    write_text(dir / "a.exr", "old image");
    write_text(dir / "a.png", "old png");
    write_text(dir / "a.json", "old stats");
    const FileState exr = state_of(dir / "a.exr"), png = state_of(dir / "a.png"),
                    json = state_of(dir / "a.json");
    auto unchanged = [&] {
        CHECK(state_of(dir / "a.exr") == exr);
        CHECK(state_of(dir / "a.png") == png);
        CHECK(state_of(dir / "a.json") == json);
        CHECK(names_in(dir.path()) == std::vector<std::string>{"a.exr", "a.json", "a.png"});
    };
    SECTION("--stats that cannot be created: refused before rendering") {
        const ProcessResult r = run_process(
            MCRT_EXE,
            with(small_render(dir / "a.exr"), {"--png", dir / "a.png", "--stats", "/proc/x.json"}),
            logs.path(), 60);
        require_one_error(r, 2, "--stats /proc/x.json");
        unchanged();
    }
    for (const std::string tmpfile : {"", "MCRT_TEST_NO_TMPFILE=1"}) {
        DYNAMIC_SECTION("the stats' write fails after the EXR's and PNG's succeeded, temporary "
                        << (tmpfile.empty() ? "unnamed" : "named")) {
            // A 4x4 EXR is about 1.2 kB, the PNG 0.1 kB, the stats about 2 kB: a 1600-byte
            // file-size limit fails the stats alone.
            std::vector<std::string> args = {MCRT_EXE, "render",      kCornell,  "--width",
                                             "4",      "--height",    "4",       "--spp",
                                             "16",     "--quiet",     "--out",   dir / "a.exr",
                                             "--png",  dir / "a.png", "--stats", dir / "a.json"};
            std::vector<std::string> env = {"MCRT_TEST_PAUSE=before-write",
                                            "MCRT_TEST_PAUSE_UNTIL=" + (logs / "go")};
            if (!tmpfile.empty()) env.push_back(tmpfile);
            fs::remove(logs / "go");
            Child child(args, env, logs / "log");
            REQUIRE(child.wait_for_text("paused at before-write", 60));
            const struct rlimit limit = {1600, 1600};
            REQUIRE(::prlimit(child.render_pid(), RLIMIT_FSIZE, &limit, nullptr) == 0);
            write_text(logs / "go", "");
            const int status = child.wait(60);
            INFO(child.output());
            REQUIRE(WIFEXITED(status));
            CHECK(WEXITSTATUS(status) == 1);
            CHECK(lines_starting_with(child.output(), "mcrt: error:").size() == 1);
            CHECK(child.output().find("a.json: cannot write") != std::string::npos);
            unchanged();
        }
    }
}

TEST_CASE("two renders into the same outputs leave one render's whole set", "[outputs][hostile]") {
    // Render 1 stops inside its commit, after its EXR is renamed; render 2 must wait for it
    // (it says so at the hook "commit-wait") and then put down its own pair.
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    auto args = [&](const std::string& seed) {
        std::vector<std::string> a =
            with(small_render(dir / "a.exr"), {"--stats", dir / "a.json", "--seed", seed});
        a.insert(a.begin(), MCRT_EXE);
        return a;
    };
    Child first(args("1"), {"MCRT_TEST_PAUSE=commit", "MCRT_TEST_PAUSE_UNTIL=" + (logs / "go")},
                logs / "log1");
    REQUIRE(first.wait_for_text("paused at commit", 60));
    Child second(args("2"), {"MCRT_TEST_PAUSE=commit-wait", "MCRT_TEST_PAUSE_SECONDS=0"},
                 logs / "log2");
    REQUIRE(second.wait_for_text("paused at commit-wait", 60));
    write_text(logs / "go", "");
    const int status1 = first.wait(60), status2 = second.wait(60);
    INFO(first.output() << second.output());
    CHECK((WIFEXITED(status1) && WEXITSTATUS(status1) == 0));
    CHECK((WIFEXITED(status2) && WEXITSTATUS(status2) == 0));
    const auto stats = nlohmann::json::parse(read_whole_file(dir / "a.json"));
    CHECK(exr_attribute(dir / "a.exr", "mcrt.seed") == "2");
    CHECK(stats["seed"] == 2);
    CHECK(names_in(dir.path()) == std::vector<std::string>{"a.exr", "a.json"});
}

TEST_CASE("one directory named two ways does not deadlock the commit", "[outputs][hostile]") {
    // flock(2) locks belong to an open file description: a directory opened once per spelling
    // would wait on its own lock forever. Each case must end, with every output written.
    TempDir temp("mcrt-hostile"), logs("mcrt-hostile-logs");
    const fs::path dir = temp.path();
    fs::create_directory(dir / "out");
    fs::create_directory_symlink(dir / "out", dir / "alias");
    const std::string mcrt = std::string(MCRT_EXE), scene = kCornell;
    const std::string render =
        "exec '" + mcrt + "' render '" + scene + "' --width 8 --height 8 --spp 16 --quiet ";
    std::string command;
    std::vector<fs::path> written;
    SECTION("relative and absolute") {
        command = "cd '" + dir.string() + "/out' && " + render + "--out o.exr --stats '" +
                  (dir / "out" / "s.json").string() + "'";
        written = {dir / "out" / "o.exr", dir / "out" / "s.json"};
    }
    SECTION("a dot component") {
        command = "cd '" + dir.string() + "' && " + render + "--out out/a.exr --png out/./a.png";
        written = {dir / "out" / "a.exr", dir / "out" / "a.png"};
    }
    SECTION("a linked directory") {
        command = render + "--out '" + (dir / "out" / "a.exr").string() + "' --stats '" +
                  (dir / "alias" / "a.json").string() + "'";
        written = {dir / "out" / "a.exr", dir / "out" / "a.json"};
    }
    SECTION("/dev/stdout redirected to a file beside a relative --out") {
        fs::create_symlink("/proc/self/fd/1", dir / "stdout");  // as /dev/stdout is
        command = "cd '" + dir.string() + "/out' && " + render + "--out o.exr --stats '" +
                  (dir / "stdout").string() + "' > s.json";
        written = {dir / "out" / "o.exr", dir / "out" / "s.json"};
    }
    const ProcessResult r = run_process("/bin/sh", {"-c", command}, logs.path(), 60);
    INFO(command << "\n" << r.err);
    REQUIRE_FALSE(r.timed_out);
    REQUIRE(r.exit_code == 0);
    for (const fs::path& file : written) {
        INFO(file);
        CHECK(fs::file_size(file) > 0);
    }
    for (const std::string& name : names_in(dir / "out"))
        CHECK(name.find(".tmp-") == std::string::npos);
}

TEST_CASE("a stop signal while another render commits into the same directory ends the wait",
          "[outputs][hostile][signals]") {
    // Render 1 holds the directory's lock inside its commit; render 2, waiting for it, is sent
    // SIGTERM: it ends with one error line and no temporary, and render 1 still lands its set.
    TempDir dir("mcrt-hostile"), logs("mcrt-hostile-logs");
    auto args = [&](const std::string& name) {
        std::vector<std::string> a =
            with(small_render(dir / (name + ".exr")), {"--stats", dir / (name + ".json")});
        a.insert(a.begin(), MCRT_EXE);
        return a;
    };
    Child first(args("a"), {"MCRT_TEST_PAUSE=commit", "MCRT_TEST_PAUSE_UNTIL=" + (logs / "go")},
                logs / "log1");
    REQUIRE(first.wait_for_text("paused at commit", 60));
    Child second(args("b"), {"MCRT_TEST_PAUSE=commit-wait", "MCRT_TEST_PAUSE_SECONDS=0"},
                 logs / "log2");
    REQUIRE(second.wait_for_text("paused at commit-wait", 60));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // into flock(2)
    second.signal(SIGTERM);
    const int status2 = second.wait(30);
    INFO(second.output());
    CHECK_FALSE(second.timed_out());
    CHECK((WIFEXITED(status2) && WEXITSTATUS(status2) == 1));
    CHECK(lines_starting_with(second.output(), "mcrt: error:").size() == 1);
    CHECK(second.output().find("stopped while another process was writing its outputs") !=
          std::string::npos);
    write_text(logs / "go", "");
    const int status1 = first.wait(60);
    CHECK((WIFEXITED(status1) && WEXITSTATUS(status1) == 0));
    CHECK(names_in(dir.path()) == std::vector<std::string>{"a.exr", "a.json"});
}
