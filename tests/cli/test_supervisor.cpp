// `mcrt render` in a supervised child (host/cli/supervisor.h): an estimator that never returns
// is stopped by the time limit or one SIGTERM or SIGINT within the grace period, and one that
// crashes its process costs one error line and exit 1; nothing is written either way. A render
// that works exits as it did without the supervisor, with the same image.
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include "cli/supervisor.h"
#include "hostile_support.h"
#include "image/image.h"
#include "process_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// An estimator file in `dir` whose estimate() runs `body`.
std::string estimator_file(const TempDir& dir, const std::string& name, const std::string& body) {
    const std::string path = dir / name;
    std::ofstream(path) << "float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
                           "                const SampleStream* stream, uint* rays) {\n"
                        << body << "\n}\n";
    return path;
}

const std::string kHang =
    "    volatile int forever = 1;\n    while (forever) {}\n    return (float3)(0.0f);";

std::vector<std::string> render_args(const std::string& out, const std::string& estimator,
                                     std::vector<std::string> extra = {}) {
    std::vector<std::string> a = {MCRT_EXE, "render", kCornell, "--width", "16", "--height",
                                  "16",     "--spp",  "16",     "--out",   out,  "--estimator-file",
                                  estimator};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
}

std::vector<std::string> names_in(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    return names;
}

// The exit status in a wait status; -1 for a death by a signal.
int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

// The render's end: exit 1, one error line holding `text`, nothing in `out_dir` (no output, no
// temporary).
void require_one_error(int code, const std::string& log, const std::string& text,
                       const TempDir& out_dir) {
    INFO(log);
    CHECK(code == 1);
    const std::vector<std::string> errors = lines_starting_with(log, "mcrt: error:");
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find(text) != std::string::npos);
    CHECK(names_in(out_dir.path()).empty());
}

// The state letter of process `pid` (proc(5): R, S, T stopped, Z ...).
char process_state(pid_t pid) {
    const std::string stat = read_whole_file("/proc/" + std::to_string(pid) + "/stat");
    const size_t paren = stat.rfind(')');
    return paren != std::string::npos && paren + 2 < stat.size() ? stat[paren + 2] : '?';
}

// Waits until process `pid` is in (or, with `in` false, out of) state `state`; false after
// `seconds`.
bool wait_for_state(pid_t pid, char state, bool in, double seconds) {
    const auto start = Clock::now();
    while (seconds_since(start) < seconds) {
        if ((process_state(pid) == state) == in) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
}

}  // namespace

TEST_CASE("a hanging estimator is stopped by the time limit within the grace period",
          "[supervisor][signals][cli]") {
    TempDir src("mcrt-sup-src"), out("mcrt-sup-out"), logs("mcrt-sup-logs");
    const std::string hang = estimator_file(src, "hang.cl", kHang);
    Child child(render_args(out / "a.exr", hang, {"--time-limit", "1"}), {}, logs / "log");
    // The progress bar's first line: the kernels are built and launched.
    REQUIRE(child.wait_for_text(" spp ", 120));
    const auto launched = Clock::now();
    const int status = child.wait(60);
    REQUIRE_FALSE(child.timed_out());
    CHECK(seconds_since(launched) < 1 + kSupervisorGraceSeconds + 3);
    require_one_error(exit_code(status), child.output(),
                      "the time limit of 1 s passed, but a launch on the devices did not return "
                      "within 5 s of it with the estimator file " +
                          hang,
                      out);
}

TEST_CASE("a hanging estimator is stopped by one SIGTERM or one SIGINT within the grace period",
          "[supervisor][signals][cli]") {
    for (int sig : {SIGTERM, SIGINT}) {
        DYNAMIC_SECTION((sig == SIGTERM ? "SIGTERM" : "SIGINT")) {
            TempDir src("mcrt-sup-src"), out("mcrt-sup-out"), logs("mcrt-sup-logs");
            const std::string hang = estimator_file(src, "hang.cl", kHang);
            Child child(render_args(out / "a.exr", hang), {}, logs / "log");
            REQUIRE(child.wait_for_text(" spp ", 120));
            child.signal(sig);
            const auto signalled = Clock::now();
            const int status = child.wait(60);
            REQUIRE_FALSE(child.timed_out());
            CHECK(seconds_since(signalled) < kSupervisorGraceSeconds + 3);
            require_one_error(exit_code(status), child.output(),
                              std::string("stopped by ") + (sig == SIGTERM ? "SIGTERM" : "SIGINT") +
                                  ", but a launch on the devices did not return within 5 s",
                              out);
        }
    }
}

TEST_CASE("an estimator that crashes its process costs one error line naming the signal",
          "[supervisor][cli]") {
    let_segv_through_sanitizer();
    const std::pair<const char*, const char*> crashes[] = {
        {"a wild global pointer",
         "    *(global volatile int*)(0x10) = 1;\n    return (float3)(0.0f);"},
        {"a private index far out of bounds",
         "    volatile float a[4];\n    volatile int i = 100000000;\n    a[i] = 1.0f;\n"
         "    return (float3)(a[0]);"}};
    for (const auto& [what, body] : crashes) {
        DYNAMIC_SECTION(what) {
            TempDir src("mcrt-sup-src"), out("mcrt-sup-out"), logs("mcrt-sup-logs");
            const std::string file = estimator_file(src, "crash.cl", body);
            std::vector<std::string> args = render_args(out / "a.exr", file, {"--quiet"});
            args.erase(args.begin());
            const ProcessResult r = run_process(MCRT_EXE, args, logs.path(), 120);
            REQUIRE_FALSE(r.timed_out);
            require_one_error(r.exit_code, r.err,
                              "the render died of signal 11 (SIGSEGV, Segmentation fault) while "
                              "the devices ran the kernels with the estimator file " +
                                  file,
                              out);
        }
    }
}

TEST_CASE("a render killed from outside with SIGKILL is one error line",
          "[supervisor][signals][cli]") {
    TempDir src("mcrt-sup-src"), out("mcrt-sup-out"), logs("mcrt-sup-logs");
    const std::string hang = estimator_file(src, "hang.cl", kHang);
    Child child(render_args(out / "a.exr", hang), {}, logs / "log");
    REQUIRE(child.wait_for_text(" spp ", 120));
    REQUIRE(child.render_pid() != child.pid());
    ::kill(child.render_pid(), SIGKILL);  // as the kernel's out-of-memory killer does
    const int status = child.wait(30);
    require_one_error(exit_code(status), child.output(),
                      "the render was killed (SIGKILL: out of memory?)", out);
}

TEST_CASE("Ctrl-Z stops the render with its supervisor and fg continues both",
          "[supervisor][signals][cli]") {
    // The render is in a process group of its own, so a terminal's SIGTSTP reaches only the
    // supervisor, which stops it too; SIGCONT goes on with both.
    TempDir src("mcrt-sup-src"), out("mcrt-sup-out"), logs("mcrt-sup-logs");
    const std::string hang = estimator_file(src, "hang.cl", kHang);
    Child child(render_args(out / "a.exr", hang), {}, logs / "log");
    REQUIRE(child.wait_for_text(" spp ", 120));
    const pid_t render = child.render_pid();
    REQUIRE(render != child.pid());
    child.signal(SIGTSTP);
    CHECK(wait_for_state(child.pid(), 'T', true, 10));
    CHECK(wait_for_state(render, 'T', true, 10));
    child.signal(SIGCONT);
    CHECK(wait_for_state(child.pid(), 'T', false, 10));
    CHECK(wait_for_state(render, 'T', false, 10));
    child.signal(SIGTERM);  // and it still stops
    const int status = child.wait(60);
    require_one_error(exit_code(status), child.output(), "stopped by SIGTERM", out);
}

TEST_CASE("a render that works exits as without the supervisor, with the same image",
          "[supervisor][cli]") {
    TempDir dir("mcrt-sup"), logs("mcrt-sup-logs");
    auto args = [&](const std::string& out) {
        return std::vector<std::string>{"render", kCornell, "--width", "32",    "--height", "24",
                                        "--spp",  "32",     "--quiet", "--out", out};
    };
    const ProcessResult supervised = run_process(MCRT_EXE, args(dir / "a.exr"), logs.path(), 120);
    setenv("MCRT_NO_SUPERVISOR", "1", 1);
    const ProcessResult alone = run_process(MCRT_EXE, args(dir / "b.exr"), logs.path(), 120);
    // Bad input: exit 2 and the one line, with or without.
    const ProcessResult bad_alone =
        run_process(MCRT_EXE, args(dir / "missing/c.exr"), logs.path(), 60);
    unsetenv("MCRT_NO_SUPERVISOR");
    const ProcessResult bad = run_process(MCRT_EXE, args(dir / "missing/c.exr"), logs.path(), 60);
    INFO(supervised.err << alone.err);
    CHECK(supervised.exit_code == 0);
    CHECK(alone.exit_code == 0);
    CHECK(supervised.err == alone.err);
    const Image a = read_exr(dir / "a.exr"), b = read_exr(dir / "b.exr");
    REQUIRE(a.rgb.size() == b.rgb.size());
    CHECK(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0);
    CHECK(bad.exit_code == 2);
    CHECK(bad.err == bad_alone.err);
    CHECK(lines_starting_with(bad.err, "mcrt: error:").size() == 1);
}

TEST_CASE("a job stopped longer than its time limit ends with what it has when continued",
          "[supervisor][signals][cli]") {
    // SIGSTOP from outside (a batch system suspending the job): the time limit is wall-clock
    // time, so the render, continued after it, stops at its next check and writes the samples
    // done; the supervisor does not count the time stopped against its grace period (it killed
    // the render on resume, losing everything).
    for (const bool both : {true, false}) {
        DYNAMIC_SECTION((both ? "supervisor and render stopped" : "render stopped alone")) {
            TempDir out("mcrt-sup-out"), logs("mcrt-sup-logs");
            Child child(
                {MCRT_EXE, "render", kCornell, "--width", "64", "--height", "48", "--spp",
                 "1000000", "--time-limit", "1", "--out", out / "a.exr", "--stats", out / "a.json"},
                {}, logs / "log");
            REQUIRE(child.wait_for_text(" spp ", 120));
            const pid_t render = child.render_pid();
            REQUIRE(render != child.pid());
            ::kill(render, SIGSTOP);
            if (both) child.signal(SIGSTOP);
            CHECK(wait_for_state(render, 'T', true, 10));
            // Past the time limit and the grace period after it.
            std::this_thread::sleep_for(
                std::chrono::duration<double>(1 + kSupervisorGraceSeconds + 1.5));
            if (both) {  // the supervisor first: it must not take the stopped render for stuck
                child.signal(SIGCONT);
                CHECK(wait_for_state(child.pid(), 'T', false, 10));
                std::this_thread::sleep_for(std::chrono::milliseconds(300));
            }
            ::kill(render, SIGCONT);
            const int status = child.wait(60);
            INFO(child.output());
            REQUIRE_FALSE(child.timed_out());
            CHECK(exit_code(status) == 0);
            CHECK(lines_starting_with(child.output(), "mcrt: error:").empty());
            REQUIRE(std::filesystem::exists(out / "a.json"));
            const Image image = read_exr(out / "a.exr");
            CHECK(image.spp > 0);
            CHECK(read_whole_file(out / "a.json").find("\"stopped_by\": \"time limit\"") !=
                  std::string::npos);
        }
    }
}

TEST_CASE("the supervisor survives a closed stderr pipe while it reports a crash",
          "[supervisor][signals][cli]") {
    let_segv_through_sanitizer();
    TempDir src("mcrt-sup-src"), out("mcrt-sup-out"), logs("mcrt-sup-logs");
    const std::string crash = estimator_file(
        src, "crash.cl", "    *(global volatile int*)(0x10) = 1;\n    return (float3)(0.0f);");
    // stdout and stderr a pipe whose reader is gone: each write fails with EPIPE.
    Child child(render_args(out / "a.exr", crash, {"--quiet"}), {}, logs / "log", true);
    const int status = child.wait(120);
    REQUIRE_FALSE(child.timed_out());
    INFO("wait status " << status);
    CHECK_FALSE(WIFSIGNALED(status));  // it died of SIGPIPE before
    CHECK(exit_code(status) == 1);
    CHECK(names_in(out.path()).empty());
}

TEST_CASE("an .icd file the ICD loader would crash or block on is named before it reads it",
          "[supervisor][cli]") {
    // ocl-icd 2.3 dies of SIGSEGV on an .icd file that starts with a NUL byte, and blocks forever
    // opening a FIFO named like one: each command that lists the devices names the file first.
    TempDir icd("mcrt-sup-icd"), logs("mcrt-sup-logs"), out("mcrt-sup-out");
    const std::string commands[][1] = {{"devices"}, {"bench"}, {"integrate"}, {"render"}};
    for (const bool fifo : {false, true}) {
        for (const auto& [command] : commands) {
            DYNAMIC_SECTION((fifo ? "a FIFO" : "a NUL byte first") << ": mcrt " << command) {
                const std::string file = icd / (fifo ? "pipe.icd" : "bad.icd");
                if (fifo)
                    REQUIRE(::mkfifo(file.c_str(), 0600) == 0);
                else
                    std::ofstream(file, std::ios::binary) << std::string(1, '\0') << "libpocl.so.2";
                std::vector<std::string> args = {command};
                if (command == "bench" || command == "render")
                    args.insert(args.end(), {kCornell, "--width", "8", "--height", "8"});
                if (command == "bench") args.insert(args.end(), {"--repeats", "1"});
                if (command == "render")
                    args.insert(args.end(), {"--quiet", "--out", out / "a.exr"});
                if (command == "integrate")
                    args.insert(args.end(),
                                {"--n", "16", "--repeats", "2", "--out", out / "i.csv"});
                setenv("OCL_ICD_VENDORS", icd.path().c_str(), 1);
                const ProcessResult r = run_process(MCRT_EXE, args, logs.path(), 60);
                unsetenv("OCL_ICD_VENDORS");
                std::filesystem::remove(file);
                INFO(r.err);
                REQUIRE_FALSE(r.timed_out);  // a FIFO: the loader blocked forever before
                CHECK(r.exit_code == 1);
                const std::vector<std::string> errors = lines_starting_with(r.err, "mcrt: error:");
                REQUIRE(errors.size() == 1);
                CHECK(errors[0].find("the OpenCL ICD file " + file) != std::string::npos);
                CHECK(errors[0].find(fifo ? "is a FIFO (named pipe)" : "starts with a NUL byte") !=
                      std::string::npos);
                CHECK(names_in(out.path()).empty());
            }
        }
    }
}

TEST_CASE("devices, bench and integrate: a driver that crashes is one error line",
          "[supervisor][cli]") {
    // PoCL 3.1 with POCL_MAX_PTHREAD_COUNT=-5 dies of SIGSEGV while listing its devices. Each
    // command runs in a supervised child: one `mcrt: error:` line naming the signal, exit 1.
    let_segv_through_sanitizer();
    TempDir logs("mcrt-sup-logs"), out("mcrt-sup-out");
    const std::vector<std::vector<std::string>> commands = {
        {"devices"},
        {"bench", kCornell, "--width", "8", "--height", "8", "--repeats", "1"},
        {"integrate", "--n", "16", "--repeats", "2", "--out", out / "i.csv"}};
    for (const auto& command : commands) {
        DYNAMIC_SECTION("POCL_MAX_PTHREAD_COUNT=-5 mcrt " << command[0]) {
            setenv("POCL_MAX_PTHREAD_COUNT", "-5", 1);
            const ProcessResult supervised = run_process(MCRT_EXE, command, logs.path(), 120);
            setenv("MCRT_NO_SUPERVISOR", "1", 1);
            const ProcessResult alone = run_process(MCRT_EXE, command, logs.path(), 120);
            unsetenv("MCRT_NO_SUPERVISOR");
            unsetenv("POCL_MAX_PTHREAD_COUNT");
            INFO("supervised: exit " << supervised.exit_code << ", " << supervised.err
                                     << "alone: signal " << alone.signal << ", " << alone.err);
            REQUIRE_FALSE(supervised.timed_out);
            CHECK(supervised.signal == 0);
            // Where the driver crashes in one process, the supervised command names it.
            if (alone.signal != 0) {
                CHECK(supervised.exit_code == 1);
                const std::vector<std::string> errors =
                    lines_starting_with(supervised.err, "mcrt: error:");
                REQUIRE(errors.size() == 1);
                CHECK(errors[0].find("mcrt " + command[0] + " died of signal " +
                                     std::to_string(alone.signal)) != std::string::npos);
                CHECK(names_in(out.path()).empty());  // integrate's CSV: no temporary left
            } else {  // a driver that copes: whatever one process did
                WARN("PoCL did not crash with POCL_MAX_PTHREAD_COUNT=-5: " << alone.err);
                CHECK(supervised.exit_code == alone.exit_code);
            }
        }
    }
}

TEST_CASE("a device whose context is refused is skipped under --device all",
          "[supervisor][cli][multidevice]") {
    // MCRT_TEST_CONTEXT_FAILURE=0 refuses device 0's context as Intel's runtime does with
    // CL_CONFIG_CPU_TARGET_ARCH=junk (CL_DEVICE_NOT_AVAILABLE).
    TempDir dir("mcrt-sup"), logs("mcrt-sup-logs");
    auto args = [&](const std::string& out, const std::string& device) {
        return std::vector<std::string>{"render", kCornell,   "--width", "24",      "--height",
                                        "16",     "--spp",    "32",      "--quiet", "--out",
                                        out,      "--device", device};
    };
    setenv("POCL_DEVICES", "pthread basic", 1);
    const ProcessResult reference =
        run_process(MCRT_EXE, args(dir / "b.exr", "1"), logs.path(), 120);
    setenv("MCRT_TEST_CONTEXT_FAILURE", "0", 1);
    const ProcessResult all = run_process(MCRT_EXE, args(dir / "a.exr", "all"), logs.path(), 120);
    const ProcessResult only = run_process(MCRT_EXE, args(dir / "c.exr", "0"), logs.path(), 120);
    unsetenv("MCRT_TEST_CONTEXT_FAILURE");
    unsetenv("POCL_DEVICES");
    INFO(reference.err << all.err << only.err);
    REQUIRE(reference.exit_code == 0);
    CHECK(all.exit_code == 0);
    const std::vector<std::string> warnings = lines_starting_with(all.err, "mcrt: warning:");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("skipping device 0") != std::string::npos);
    CHECK(warnings[0].find("clCreateContext failed with CL_DEVICE_NOT_AVAILABLE") !=
          std::string::npos);
    const Image a = read_exr(dir / "a.exr"), b = read_exr(dir / "b.exr");
    REQUIRE(a.rgb.size() == b.rgb.size());
    CHECK(std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0);
    // The only device: the render cannot go on.
    CHECK(only.exit_code == 1);
    CHECK(lines_starting_with(only.err, "mcrt: error:").size() == 1);
    CHECK(only.err.find("clCreateContext failed") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "c.exr"));
}
