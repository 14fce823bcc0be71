// A render stopped by SIGTERM, SIGINT or SIGHUP at any moment — loading the scene, building
// kernels, rendering, writing — leaves either no output file or a complete, valid EXR (of whole
// chunk rows), never a truncated one, and no temporary file behind (DESIGN.md "Exit status").
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "hostile_support.h"
#include "image/image.h"
#include "process_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

// Files in `dir` besides the captured stdout/stderr of run_process.
std::vector<std::string> files_in(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("stdout-", 0) != 0 && name.rfind("stderr-", 0) != 0) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    return names;
}

// What a stopped render left in its own directory: nothing, or a whole EXR and stats JSON.
void check_outputs(const std::filesystem::path& dir, const ProcessResult& r, int width,
                   int height) {
    const std::string exr = (dir / "out.exr").string();
    const std::vector<std::string> left = files_in(dir);
    INFO("exit " << r.exit_code << ", signal " << r.signal << ", after " << r.seconds
                 << " s; stderr: " << r.err);
    REQUIRE_FALSE(r.timed_out);
    if (r.exit_code == 0) {
        // Stopped after rendering started: the samples done so far, in whole chunks.
        CHECK(left == std::vector<std::string>{"out.exr", "out.json"});
        const Image img = read_exr(exr);
        CHECK(img.width == width);
        CHECK(img.height == height);
        const uint32_t spp = static_cast<uint32_t>(img.spp);
        CHECK(double(spp) == img.spp);
        CHECK(spp > 0);
        CHECK(spp % 16 == 0);
        REQUIRE(img.rgb.size() == size_t(3) * width * height);
        for (float v : img.rgb) REQUIRE(std::isfinite(v));
        for (float v : img.variance) REQUIRE(std::isfinite(v));
        const nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "out.json"));
        CHECK(stats["spp"].get<uint32_t>() == spp);
    } else {
        // Ended by the signal before rendering started (default action), or stopped with one
        // `mcrt: error:` line (interrupted before the first chunk row): no output at all.
        const bool ended_cleanly =
            r.signal != 0 ||
            (r.exit_code == 1 && lines_starting_with(r.err, "mcrt: error:").size() == 1);
        CHECK(ended_cleanly);
        CHECK(left.empty());
    }
}

}  // namespace

TEST_CASE("SIGTERM or SIGINT at any moment leaves no output or a whole EXR", "[signals][cli]") {
    const int width = 64, height = 48;
    for (int signal : {SIGTERM, SIGINT}) {
        for (double after : {0.0, 0.05, 0.3, 1.0, 2.5}) {
            DYNAMIC_SECTION((signal == SIGTERM ? "SIGTERM" : "SIGINT")
                            << " after " << after << " s") {
                TempDir dir("mcrt-signals");
                const ProcessResult r =
                    run_process(MCRT_EXE,
                                {"render", kCornell, "--width", std::to_string(width), "--height",
                                 std::to_string(height), "--spp", "1000000", "--quiet", "--out",
                                 dir / "out.exr", "--stats", dir / "out.json"},
                                dir.path(), 90, signal, after);
                check_outputs(dir.path(), r, width, height);
                // A signal during the render stops it with a warning and exit 0.
                if (r.exit_code == 0)
                    CHECK(r.err.find("stopped by interrupt") != std::string::npos);
            }
        }
    }
}

TEST_CASE("A render that finishes under a late SIGTERM still writes its whole image",
          "[signals][cli]") {
    // A short render: the signal arrives while writing or after exit; either way the file is whole.
    TempDir dir("mcrt-signals");
    const ProcessResult r =
        run_process(MCRT_EXE,
                    {"render", kCornell, "--width", "32", "--height", "32", "--spp", "16",
                     "--quiet", "--out", dir / "out.exr", "--stats", dir / "out.json"},
                    dir.path(), 90, SIGTERM, 1.5);
    check_outputs(dir.path(), r, 32, 32);
}

TEST_CASE("SIGTERM ends a render on a slow device within seconds", "[signals][cli]") {
    // MCRT_SLOW_DEVICE=0:40 makes device 0 forty times slower (each launch sleeps 39 times its
    // busy time). Launches are sized by the device's own measured speed to about 150 ms, so a
    // stop is seen within a launch or two; the first chunk of every pixel is still finished, unless
    // that is more than 3 s away: then the render is abandoned, writing nothing.
    setenv("MCRT_SLOW_DEVICE", "0:40", 1);
    for (int size : {64, 512}) {
        DYNAMIC_SECTION(size << "x" << size) {
            TempDir dir("mcrt-signals");
            // Late enough that a cold kernel build (in this process, on PoCL) is over.
            const double after = 8.0;
            const ProcessResult r = run_process(
                MCRT_EXE,
                {"render", kCornell, "--width", std::to_string(size), "--height",
                 std::to_string(size), "--spp", "4096", "--estimator", "mis", "--max-depth", "4",
                 "--quiet", "--out", dir / "out.exr", "--stats", dir / "out.json"},
                dir.path(), 120, SIGTERM, after);
            check_outputs(dir.path(), r, size, size);
            CHECK(r.seconds < after + 6.0);  // the 3 s grace, a launch, the exit
            if (size == 64) {                // the first chunk row is done well before the signal
                CHECK(r.exit_code == 0);
            } else {  // 512x512x16 samples at this speed take about a minute
                CHECK(r.exit_code == 1);
                CHECK(r.err.find("before every pixel had its first 16 samples") !=
                      std::string::npos);
            }
        }
    }
    unsetenv("MCRT_SLOW_DEVICE");
}

TEST_CASE("SIGHUP mid-render stops it as SIGINT does: the samples done, written, exit 0",
          "[signals][cli][supervisor]") {
    // A closed terminal or ssh session. The render's progress bar shows that the kernels run.
    TempDir dir("mcrt-signals"), logs("mcrt-signals-logs");
    Child child({MCRT_EXE, "render", kCornell, "--width", "64", "--height", "48", "--spp",
                 "1000000", "--out", dir / "out.exr", "--stats", dir / "out.json"},
                {}, logs / "log");
    REQUIRE(child.wait_for_text(" spp ", 120));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    child.signal(SIGHUP);
    const int status = child.wait(60);
    INFO(child.output());
    REQUIRE_FALSE(child.timed_out());
    REQUIRE(WIFEXITED(status));  // it died of SIGHUP (129) before
    CHECK(WEXITSTATUS(status) == 0);
    CHECK(child.output().find("stopped by interrupt") != std::string::npos);
    ProcessResult as_if;  // check_outputs' view of it
    as_if.exit_code = WEXITSTATUS(status);
    as_if.err = child.output();
    check_outputs(dir.path(), as_if, 64, 48);
    CHECK(files_in(dir.path()) == std::vector<std::string>{"out.exr", "out.json"});
    const nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "out.json"));
    CHECK(stats["stopped_by"] == "interrupt");
}

TEST_CASE("under nohup (SIGHUP ignored) a SIGHUP leaves the render to finish",
          "[signals][cli][supervisor]") {
    TempDir dir("mcrt-signals"), logs("mcrt-signals-logs");
    struct sigaction ignore {
    }, old{};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    sigaction(SIGHUP, &ignore, &old);  // inherited across posix_spawn and exec, as nohup does
    Child child({MCRT_EXE, "render", kCornell, "--width", "32", "--height", "32", "--spp", "4096",
                 "--out", dir / "out.exr", "--stats", dir / "out.json"},
                {}, logs / "log");
    sigaction(SIGHUP, &old, nullptr);
    REQUIRE(child.wait_for_text(" spp ", 120));
    child.signal(SIGHUP);
    ::kill(child.render_pid(), SIGHUP);
    const int status = child.wait(120);
    INFO(child.output());
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    const nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "out.json"));
    CHECK(stats["spp"] == 4096);
    CHECK(stats["stopped_by"] == "");
}
