// One render across the ranks of an MPI job (docs/MPI.md): the image must be bitwise identical to
// a one-process render, every rank must do work, a time limit, a signal to rank 0 and a device
// fault on one rank must behave as they do on one machine, bad input must end every rank with
// one error line, and the death of a rank must end the job rather than hang it. Skipped when mcrt
// was built without MPI or mpirun is not installed; the message format is tested in every build.
#include <dirent.h>

#include <catch2/catch.hpp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <thread>

#include "common/error.h"
#include "image/image.h"
#include "mpi/wire.h"
#include "process_support.h"
#include "test_support.h"

using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

// mpirun on PATH, or a skip: when mcrt was built without MPI, or MPI is not installed.
std::string mpirun() {
#ifndef MCRT_HAVE_MPI
    skip_test("mcrt was built without MPI (CMake found none)");
#endif
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "/usr/bin:/bin";
    for (size_t at = 0; at <= dirs.size();) {
        size_t end = dirs.find(':', at);
        if (end == std::string::npos) end = dirs.size();
        std::string candidate = dirs.substr(at, end - at) + "/mpirun";
        if (::access(candidate.c_str(), X_OK) == 0) return candidate;
        at = end + 1;
    }
    skip_test("mpirun is not installed (Debian: openmpi-bin)");
}

// For every child: root may run mpirun (CI runs as root), ranks oversubscribe the two cores, and
// no single-copy mechanism between ranks (CMA's process_vm_readv is refused in containers).
const bool mpi_environment = [] {
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
    setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
    unsetenv("MCRT_FAULT_INJECT");
    unsetenv("POCL_DEVICES");
    return true;
}();

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

std::vector<std::string> render_args(const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> a = {"render", kCornell, "--width", "48",    "--height", "40",
                                  "--spp",  "64",     "--quiet", "--out", out};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
}

// `mpirun -n ranks mcrt ARGS...`
ProcessResult run_mpi(int ranks, const std::vector<std::string>& mcrt_args, const TempDir& dir,
                      double timeout = 60) {
    // --bind-to none: OpenMPI binds each of up to 2 ranks to one core by default, which halves
    // a rank's CPU device (docs/MPI.md).
    std::vector<std::string> a = {"--bind-to",           "none",  "--oversubscribe", "-n",
                                  std::to_string(ranks), MCRT_EXE};
    a.insert(a.end(), mcrt_args.begin(), mcrt_args.end());
    return run_process(mpirun(), a, dir.path(), timeout);
}

// The pids of the mcrt processes of an mpirun whose environment holds `marker` (the test's own
// MCRT_TEST_MPI_MARKER value), with their rank.
std::vector<std::pair<int, pid_t>> ranks_with_marker(const std::string& marker) {
    std::vector<std::pair<int, pid_t>> found;
    DIR* proc = opendir("/proc");
    if (!proc) return found;
    while (dirent* e = readdir(proc)) {
        pid_t pid = std::atoi(e->d_name);
        if (pid <= 0) continue;
        std::string env = read_whole_file("/proc/" + std::to_string(pid) + "/environ");
        if (env.find("MCRT_TEST_MPI_MARKER=" + marker + '\0') == std::string::npos) continue;
        const std::string key = std::string("OMPI_COMM_WORLD_RANK=");
        size_t at = env.find(key);
        if (at == std::string::npos) continue;
        found.emplace_back(std::atoi(env.c_str() + at + key.size()), pid);
    }
    closedir(proc);
    return found;
}

// Sends `signal` to rank `rank` of the job marked `marker` once it has rendered for a while
// (`after` seconds after that rank appears).
std::thread signal_rank_later(const std::string& marker, int rank, int signal, double after) {
    return std::thread([=] {
        auto start = std::chrono::steady_clock::now();
        while (std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
            for (auto [r, pid] : ranks_with_marker(marker))
                if (r == rank) {
                    std::this_thread::sleep_for(std::chrono::duration<double>(after));
                    kill(pid, signal);
                    return;
                }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    });
}

// The 64×64 Cornell box of `spp` samples rendered by one process into dir/full.exr: what an
// MPI render stopped after spp samples must equal bit for bit.
Image one_process_render(const TempDir& dir, uint32_t spp) {
    ProcessResult r = run_process(MCRT_EXE,
                                  {"render", kCornell, "--width", "64", "--height", "64", "--spp",
                                   std::to_string(spp), "--quiet", "--out", dir / "full.exr"},
                                  dir.path(), 120);
    REQUIRE(r.exit_code == 0);
    return read_exr(dir / "full.exr");
}

}  // namespace

TEST_CASE("MPI messages: inputs, hellos, items and results read back as written", "[mpi]") {
    FileBundle files = {{"a/scene.gltf", {'{', '}'}}, {"a/b.bin", {0, 1, 2, 255}}, {"empty", {}}};
    FileBundle files_back;
    std::string source_back;
    wire::decode_inputs(wire::encode_inputs(files, "float3 estimate"), files_back, source_back);
    CHECK(files_back == files);
    CHECK(source_back == "float3 estimate");

    wire::Hello hello{"node7", {{0, "pthread-cpu"}, {3, "gpu"}}, {"a warning"}};
    wire::Hello hello_back = wire::decode_hello(wire::encode_hello(hello));
    CHECK(hello_back.host == "node7");
    CHECK(hello_back.devices == hello.devices);
    CHECK(hello_back.warnings == hello.warnings);

    WorkItem item{42, 3, 4, 100, 164};
    wire::Bytes item_bytes = wire::encode_item(item);
    CHECK(item_bytes.size() == 40);
    std::optional<WorkItem> item_back = wire::decode_item(item_bytes);
    REQUIRE(item_back);
    CHECK(item_back->seq == 42);
    CHECK(item_back->chunk_begin == 3);
    CHECK(item_back->chunk_end == 4);
    CHECK(item_back->pixel_begin == 100);
    CHECK(item_back->pixel_end == 164);
    CHECK_FALSE(wire::decode_item(wire::encode_item(std::nullopt)));

    wire::ResultMessage m;
    m.target_samples = 5000;
    m.samples = 64 * 16;
    m.seconds_busy = 0.25;
    m.seconds_run = 0.5;
    m.result.item = item;
    for (int k = 0; k < 64; ++k) {
        gpu::ChunkSums c{};
        c.shift = {float(k), 1.5f, -2.0f, 0.0f};
        c.sum = {float(k * k), 2.25f, 4.0f, 7.0f};
        c.exponent = {1.0f, 2.0f, 3.0f, 0.0f};
        m.result.sums.push_back(c);
    }
    wire::Bytes result_bytes = wire::encode_result(m);
    CHECK(result_bytes.size() == 80 + 64 * 64);
    wire::ResultMessage back = wire::decode_result(result_bytes, item);
    CHECK_FALSE(back.failed);
    CHECK(back.target_samples == 5000);
    CHECK(back.samples == 1024);
    CHECK(back.seconds_run == 0.5);
    REQUIRE(back.result.sums.size() == 64);
    CHECK(std::memcmp(back.result.sums.data(), m.result.sums.data(), 64 * 64) == 0);
    // The result of another item, a cut message, a failure.
    WorkItem other = item;
    other.seq = 43;
    CHECK_THROWS_AS(wire::decode_result(result_bytes, other), RuntimeError);
    result_bytes.pop_back();
    CHECK_THROWS_AS(wire::decode_result(result_bytes, item), RuntimeError);
    wire::ResultMessage failure;
    failure.failed = true;
    failure.error = "CL_OUT_OF_RESOURCES";
    wire::ResultMessage failure_back = wire::decode_result(wire::encode_result(failure), item);
    CHECK(failure_back.failed);
    CHECK(failure_back.error == "CL_OUT_OF_RESOURCES");
}

TEST_CASE("the scene loaded from a bundle of the files rank 0 read is the same scene", "[mpi]") {
    FileBundle files;
    Scene a = load_gltf(kCornell, {}, nullptr, &files);
    REQUIRE(files.size() == 2);  // the .gltf and its .bin
    Scene b = load_gltf_from_bundle(kCornell, files, {});
    CHECK(a.triangle_count() == b.triangle_count());
    REQUIRE(a.positions.size() == b.positions.size());
    CHECK(std::memcmp(a.positions.data(), b.positions.data(),
                      a.positions.size() * sizeof(a.positions[0])) == 0);
    files.erase(std::prev(files.end()));  // one file missing: an InputError, nothing read from disk
    CHECK_THROWS_AS(load_gltf_from_bundle(kCornell, files, {}), InputError);
}

TEST_CASE("mpirun -n 3 renders the image of one process, bit for bit, every rank working",
          "[mpi][cli]") {
    const std::string launcher = mpirun();
    TempDir dir;
    ProcessResult one = run_process(MCRT_EXE, render_args(dir / "one.exr"), dir.path());
    REQUIRE(one.exit_code == 0);
    ProcessResult three =
        run_mpi(3, render_args(dir / "three.exr", {"--stats", dir / "three.json"}), dir);
    INFO("stderr: " << three.err);
    REQUIRE(three.exit_code == 0);
    // --quiet: no rank prints anything of its own (mpirun may add notes of its own machine).
    CHECK(lines_starting_with(three.err, "mcrt:").empty());
    Image a = read_exr(dir / "one.exr"), b = read_exr(dir / "three.exr");
    CHECK(same_bits(a.rgb, b.rgb));
    CHECK(same_bits(a.variance, b.variance));
    nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "three.json"));
    REQUIRE(stats["ranks"].size() == 3);
    uint64_t samples = 0;
    for (const auto& r : stats["ranks"]) {
        INFO(r.dump());
        CHECK(r["samples"].get<uint64_t>() > 0);
        CHECK(r["items"].get<uint64_t>() > 0);
        CHECK(r["devices"] == 1);
        CHECK(r.contains("host"));
        CHECK(r.contains("seconds_busy"));
        samples += r["samples"].get<uint64_t>();
    }
    CHECK(samples == 48u * 40u * 64u);
    CHECK(stats["ranks"][1]["message_bytes"].get<uint64_t>() > 0);
}

TEST_CASE("mpirun -n 2 renders the path-traced image of one process under the sky light",
          "[mpi][cli][paths]") {
    // Every rank derives --max-depth, --rr-depth, --sky and the --look-from camera from the same
    // command line; the path records come back in the runs' sums.
    TempDir dir;
    const std::vector<std::string> paths = {"--max-depth", "8",     "--rr-depth",  "2",
                                            "--sky",       "0.4",   "--look-from", "0,1,5",
                                            "--look-at",   "0,1,0", "--estimator", "mis"};
    auto with = [&](std::vector<std::string> extra) {
        extra.insert(extra.end(), paths.begin(), paths.end());
        return extra;
    };
    ProcessResult one = run_process(
        MCRT_EXE, render_args(dir / "one.exr", with({"--stats", dir / "one.json"})), dir.path());
    REQUIRE(one.exit_code == 0);
    ProcessResult two =
        run_mpi(2, render_args(dir / "two.exr", with({"--stats", dir / "two.json"})), dir);
    INFO("stderr: " << two.err);
    REQUIRE(two.exit_code == 0);
    Image a = read_exr(dir / "one.exr"), b = read_exr(dir / "two.exr");
    CHECK(same_bits(a.rgb, b.rgb));
    CHECK(same_bits(a.variance, b.variance));
    nlohmann::json sa = nlohmann::json::parse(read_whole_file(dir / "one.json"));
    nlohmann::json sb = nlohmann::json::parse(read_whole_file(dir / "two.json"));
    CHECK(sa["rays"] == sb["rays"]);
    CHECK(sa["mean_path_length"] == sb["mean_path_length"]);
    CHECK(sa["roulette_share"] == sb["roulette_share"]);
    CHECK(sb["roulette_share"].get<double>() > 0.0);
}

TEST_CASE("mpirun -n 2 renders the image of one process under an environment map", "[mpi][cli]") {
    // Rank 0 reads the map and ships its bytes with the scene's: the other rank reads it from
    // that bundle, never from the disk (a map missing from it is an error there).
    TempDir dir;
    Image map(16, 8);
    for (size_t k = 0; k < map.rgb.size(); ++k) map.rgb[k] = k % 48 < 6 ? 40.0f : 0.3f;
    write_exr(dir / "map.exr", map);
    const std::vector<std::string> env = {
        "--env",       dir / "map.exr", "--env-rotate", "20",    "--max-depth", "3",
        "--look-from", "0,1,5",         "--look-at",    "0,1,0", "--estimator", "mis"};
    std::vector<std::string> one_args = render_args(dir / "one.exr", env);
    ProcessResult one = run_process(MCRT_EXE, one_args, dir.path());
    INFO("stderr: " << one.err);
    REQUIRE(one.exit_code == 0);
    ProcessResult two = run_mpi(2, render_args(dir / "two.exr", env), dir);
    INFO("stderr: " << two.err);
    REQUIRE(two.exit_code == 0);
    Image a = read_exr(dir / "one.exr"), b = read_exr(dir / "two.exr");
    CHECK(same_bits(a.rgb, b.rgb));
    CHECK(same_bits(a.variance, b.variance));
}

TEST_CASE("mpirun -n 2 renders punctual lights as one process does, bit for bit",
          "[mpi][cli][punctual]") {
    // Every rank reads the KHR_lights_punctual lights from the bundle and builds the same
    // light tree over them and the area light.
    TempDir dir;
    const std::string scene = std::string(MCRT_SCENES) + "/punctual/punctual-lights.gltf";
    auto args = [&](const std::string& out) {
        return std::vector<std::string>{"render",
                                        scene,
                                        "--width",
                                        "40",
                                        "--height",
                                        "32",
                                        "--spp",
                                        "32",
                                        "--estimator",
                                        "mis",
                                        "--light-select",
                                        "tree",
                                        "--max-depth",
                                        "3",
                                        "--quiet",
                                        "--out",
                                        out};
    };
    ProcessResult one = run_process(MCRT_EXE, args(dir / "one.exr"), dir.path());
    REQUIRE(one.exit_code == 0);
    ProcessResult two = run_mpi(2, args(dir / "two.exr"), dir);
    INFO("stderr: " << two.err);
    REQUIRE(two.exit_code == 0);
    Image a = read_exr(dir / "one.exr"), b = read_exr(dir / "two.exr");
    CHECK(same_bits(a.rgb, b.rgb));
    CHECK(same_bits(a.variance, b.variance));
}

TEST_CASE("two ranks of two devices each render the image of one process", "[mpi][cli]") {
    mpirun();
    TempDir dir;
    ProcessResult one = run_process(MCRT_EXE, render_args(dir / "one.exr"), dir.path());
    REQUIRE(one.exit_code == 0);
    setenv("POCL_DEVICES", "pthread basic", 1);
    ProcessResult two = run_mpi(
        2, render_args(dir / "two.exr", {"--device", "all", "--stats", dir / "two.json"}), dir);
    unsetenv("POCL_DEVICES");
    INFO("stderr: " << two.err);
    REQUIRE(two.exit_code == 0);
    CHECK(same_bits(read_exr(dir / "one.exr").rgb, read_exr(dir / "two.exr").rgb));
    nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "two.json"));
    REQUIRE(stats["ranks"].size() == 2);
    CHECK(stats["ranks"][0]["devices"] == 2);
    CHECK(stats["ranks"][1]["devices"] == 2);
    CHECK(stats["devices"].size() == 4);
}

TEST_CASE("a device fault on one rank retires it and leaves the image unchanged", "[mpi][cli]") {
    const std::string launcher = mpirun();
    TempDir dir;
    ProcessResult one = run_process(MCRT_EXE, render_args(dir / "one.exr"), dir.path());
    REQUIRE(one.exit_code == 0);
    // MPMD: rank 1 alone has the fault switch (its device 0 fails at its first launch).
    std::vector<std::string> a = {"--oversubscribe", "-n", "1", MCRT_EXE};
    std::vector<std::string> r = render_args(dir / "faulty.exr", {"--stats", dir / "f.json"});
    a.insert(a.end(), r.begin(), r.end());
    a.insert(a.end(), {":", "-n", "1", "env", "MCRT_FAULT_INJECT=0:1", MCRT_EXE});
    a.insert(a.end(), r.begin(), r.end());
    ProcessResult faulty = run_process(launcher, a, dir.path(), 60);
    INFO("stderr: " << faulty.err);
    REQUIRE(faulty.exit_code == 0);
    std::vector<std::string> warnings = lines_starting_with(faulty.err, "mcrt: warning:");
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("rank 1 device 0") != std::string::npos);
    CHECK(warnings[0].find("retired") != std::string::npos);
    CHECK(warnings[0].find("CL_OUT_OF_RESOURCES") != std::string::npos);
    CHECK(same_bits(read_exr(dir / "one.exr").rgb, read_exr(dir / "faulty.exr").rgb));
    nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "f.json"));
    CHECK(stats["ranks"][1]["devices_retired"] == 1);
    CHECK(stats["ranks"][1]["samples"] == 0);
    CHECK(stats["ranks"][0]["samples"] == 48 * 40 * 64);
}

TEST_CASE("bad input under mpirun: every rank exits 2, with one error line", "[mpi][cli]") {
    mpirun();
    TempDir dir;
    struct Case {
        const char* what;
        std::vector<std::string> args;
    };
    std::vector<Case> cases = {
        {"missing scene", {"render", dir / "none.gltf", "--out", dir / "x.exr"}},
        {"unknown option", {"render", kCornell, "--out", dir / "x.exr", "--no-such-option"}},
        {"bad camera", {"render", kCornell, "--out", dir / "x.exr", "--camera", "9"}},
        // Read into the request after parsing: each rank reads them, rank 0 alone says so.
        {"bad sky", {"render", kCornell, "--out", dir / "x.exr", "--sky", "abc"}},
        {"bad look-from",
         {"render", kCornell, "--out", dir / "x.exr", "--look-from", "1,2", "--look-at", "0,0,0"}},
        {"estimator that does not build",
         {"render", kCornell, "--out", dir / "x.exr", "--width", "8", "--height", "8",
          "--estimator-file", dir / "bad.cl"}},
    };
    {
        std::ofstream bad(dir / "bad.cl");
        bad << "float3 estimate(this is not C\n";
    }
    for (const Case& c : cases) {
        ProcessResult r = run_mpi(2, c.args, dir, 60);
        INFO(c.what << "; stderr: " << r.err);
        CHECK(!r.timed_out);
        CHECK(r.exit_code == 2);
        CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
        CHECK(!std::filesystem::exists(dir / "x.exr"));
    }
}

TEST_CASE("an estimator that crashes under mpirun: an error line per rank naming the signal",
          "[mpi][cli][supervisor]") {
    // Each rank's supervisor (host/cli/supervisor.h) outlives its render's SIGSEGV: one line
    // (rank 0's, then "rank 1: ..."), and mpirun ends the job with a non-zero status.
    mpirun();
    let_segv_through_sanitizer();
    TempDir dir;
    {
        std::ofstream crash(dir / "crash.cl");
        crash << "float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
                 "                const SampleStream* stream, uint* rays) {\n"
                 "    *(global volatile int*)(0x10) = 1;\n    return (float3)(0.0f);\n}\n";
    }
    ProcessResult r =
        run_mpi(2,
                {"render", kCornell, "--out", dir / "x.exr", "--width", "16", "--height", "16",
                 "--spp", "16", "--quiet", "--estimator-file", dir / "crash.cl"},
                dir, 60);
    INFO("stderr: " << r.err);
    CHECK(!r.timed_out);
    CHECK(r.exit_code != 0);
    const std::vector<std::string> errors = lines_starting_with(r.err, "mcrt: error:");
    REQUIRE(!errors.empty());
    CHECK(errors.size() <= 2);
    for (const std::string& e : errors)
        CHECK(e.find("died of signal 11 (SIGSEGV") != std::string::npos);
    CHECK(!std::filesystem::exists(dir / "x.exr"));
}

TEST_CASE(
    "under mpirun a time limit or SIGINT to rank 0 stops every rank and writes the "
    "whole chunks done",
    "[mpi][cli]") {
    mpirun();
    TempDir dir;
    for (int how : {0, 1}) {
        const std::string exr = dir / ("partial" + std::to_string(how) + ".exr");
        std::vector<std::string> args = {
            "render", kCornell,  "--width",           "64",      "--height",
            "64",     "--spp",   "1000000",           "--quiet", "--out",
            exr,      "--stats", dir / "partial.json"};
        const std::string marker = dir.path().string() + std::to_string(how);
        setenv("MCRT_TEST_MPI_MARKER", marker.c_str(), 1);
        std::thread signaller;
        if (how == 0)
            args.insert(args.end(), {"--time-limit", "2"});
        else
            signaller = signal_rank_later(marker, 0, SIGINT, 3.0);
        ProcessResult r = run_mpi(2, args, dir, 60);
        if (signaller.joinable()) signaller.join();
        unsetenv("MCRT_TEST_MPI_MARKER");
        INFO((how == 0 ? "time limit" : "SIGINT") << "; stderr: " << r.err);
        REQUIRE(r.exit_code == 0);
        CHECK(r.seconds < 30);
        Image img = read_exr(exr);
        nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "partial.json"));
        const uint32_t spp = stats["spp"].get<uint32_t>();
        CHECK(stats["stopped_by"] == (how == 0 ? "time limit" : "interrupt"));
        CHECK(spp > 0);
        CHECK(spp % 16 == 0);
        CHECK(img.spp == spp);
        CHECK(stats["ranks"][1]["samples"].get<uint64_t>() > 0);
        // Exactly the render of spp samples by one process.
        CHECK(same_bits(img.rgb, one_process_render(dir, spp).rgb));
    }
}

TEST_CASE("a rank killed mid-render ends the job: mpirun exits non-zero, nothing is written",
          "[mpi][cli]") {
    // MPI's own semantics (docs/MPI.md "When a rank dies"): OpenMPI's mpirun sees the process
    // die and ends the job, rank 0 included, before rank 0 can notice through MPI.
    mpirun();
    TempDir dir;
    const std::string marker = dir.path().string() + "kill";
    setenv("MCRT_TEST_MPI_MARKER", marker.c_str(), 1);
    std::thread killer = signal_rank_later(marker, 1, SIGKILL, 3.0);
    ProcessResult r = run_mpi(2,
                              {"render", kCornell, "--width", "64", "--height", "64", "--spp",
                               "1000000", "--quiet", "--out", dir / "killed.exr"},
                              dir, 60);
    killer.join();
    unsetenv("MCRT_TEST_MPI_MARKER");
    INFO("stderr: " << r.err);
    CHECK(!r.timed_out);
    CHECK(r.exit_code != 0);
    CHECK(!std::filesystem::exists(dir / "killed.exr"));
}

TEST_CASE(
    "with mpirun --enable-recovery rank 0 outlives a killed rank, redoes its work and "
    "writes the image",
    "[mpi][cli]") {
    const std::string launcher = mpirun();
    TempDir dir;
    const std::string marker = dir.path().string() + "recover";
    setenv("MCRT_TEST_MPI_MARKER", marker.c_str(), 1);
    setenv("MCRT_MPI_TIMEOUT", "2", 1);
    std::thread killer = signal_rank_later(marker, 1, SIGKILL, 2.0);
    ProcessResult r = run_process(launcher,
                                  {"--enable-recovery",
                                   "--oversubscribe",
                                   "-n",
                                   "2",
                                   MCRT_EXE,
                                   "render",
                                   kCornell,
                                   "--width",
                                   "64",
                                   "--height",
                                   "64",
                                   "--spp",
                                   "1000000",
                                   "--quiet",
                                   "--time-limit",
                                   "6",
                                   "--out",
                                   dir / "recovered.exr",
                                   "--stats",
                                   dir / "recovered.json"},
                                  dir.path(), 60);
    killer.join();
    unsetenv("MCRT_TEST_MPI_MARKER");
    unsetenv("MCRT_MPI_TIMEOUT");
    INFO("stderr: " << r.err);
    CHECK(!r.timed_out);
    CHECK(r.err.find("taken for dead") != std::string::npos);
    CHECK(r.err.find("rank 1 was lost; ending the job with MPI_Abort") != std::string::npos);
    // mpirun's own status after MPI_Abort under --enable-recovery is 0 with OpenMPI 4.1: not
    // checked. The image is that of one process with as many samples.
    nlohmann::json stats = nlohmann::json::parse(read_whole_file(dir / "recovered.json"));
    const uint32_t spp = stats["spp"].get<uint32_t>();
    CHECK(stats["stopped_by"] == "time limit");
    CHECK(stats["ranks"][1]["devices_retired"] == 1);
    REQUIRE(spp > 0);
    CHECK(same_bits(read_exr(dir / "recovered.exr").rgb, one_process_render(dir, spp).rgb));
}

namespace {

// `mpirun -n 1 mcrt RANK0... : -n 1 mcrt RANK1...` (MPMD: each rank its own command line).
ProcessResult run_mpmd(const std::vector<std::string>& rank0, const std::vector<std::string>& rank1,
                       const TempDir& dir, double timeout = 60) {
    std::vector<std::string> a = {"--bind-to", "none", "--oversubscribe", "-n", "1", MCRT_EXE};
    a.insert(a.end(), rank0.begin(), rank0.end());
    a.insert(a.end(), {":", "-n", "1", MCRT_EXE});
    a.insert(a.end(), rank1.begin(), rank1.end());
    return run_process(mpirun(), a, dir.path(), timeout);
}

}  // namespace

TEST_CASE("a rank started with other options ends the job at once, naming the option",
          "[mpi][cli]") {
    // Rank 0's command line is the request: a rank that reads another (it rendered its items
    // with its own image size, estimator or seed: a wrong image, exit 0) or refuses its own
    // (--spp 0: rank 0 waited 120 s for it) is one error line and exit 2 on every rank.
    mpirun();
    TempDir dir;
    struct Case {
        const char* what;
        std::vector<std::string> rank1_extra;
        const char* said;
    };
    const std::vector<Case> cases = {
        {"image size",
         {"--width", "32"},
         "rank 1 was started with --width 32, rank 0 with --width 48"},
        {"estimator",
         {"--estimator", "mis"},
         "rank 1 was started with --estimator mis, rank 0 with --estimator light-area"},
        {"seed", {"--seed", "7"}, "rank 1 was started with --seed 7, rank 0 with --seed 0"},
        {"an output only rank 1 names", {"--png", dir / "x.png"}, "rank 1 was started with --png"},
        {"an invalid value",
         {"--spp", "0"},
         "rank 1 refused its command line: --spp: Value 0 not in range"},
        {"an unknown option", {"--no-such-option"}, "rank 1 refused its command line: "},
    };
    for (const Case& c : cases) {
        DYNAMIC_SECTION(c.what) {
            std::vector<std::string> rank0 = {"render",  kCornell, "--height",   "40",
                                              "--quiet", "--out",  dir / "x.exr"};
            std::vector<std::string> rank1 = rank0;
            rank0.insert(rank0.end(), {"--width", "48"});
            if (c.rank1_extra.front() != "--width") rank1.insert(rank1.end(), {"--width", "48"});
            rank1.insert(rank1.end(), c.rank1_extra.begin(), c.rank1_extra.end());
            const auto start = std::chrono::steady_clock::now();
            const ProcessResult r = run_mpmd(rank0, rank1, dir, 90);
            const double seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            INFO("stderr: " << r.err);
            REQUIRE_FALSE(r.timed_out);
            CHECK(r.exit_code == 2);
            CHECK(seconds < 30);  // not rank 0's 120 s wait for a rank that never comes
            const std::vector<std::string> errors = lines_starting_with(r.err, "mcrt: error:");
            REQUIRE(errors.size() == 1);
            CHECK(errors[0].find(c.said) != std::string::npos);
            CHECK_FALSE(std::filesystem::exists(dir / "x.exr"));
            CHECK_FALSE(std::filesystem::exists(dir / "x.png"));
        }
    }
}

TEST_CASE("ranks may differ in --device alone, and another command on a rank ends the job",
          "[mpi][cli]") {
    mpirun();
    TempDir dir;
    ProcessResult one = run_process(MCRT_EXE, render_args(dir / "one.exr"), dir.path());
    REQUIRE(one.exit_code == 0);
    const ProcessResult r = run_mpmd(render_args(dir / "two.exr", {"--device", "0"}),
                                     render_args(dir / "two.exr", {"--device", "all"}), dir);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(same_bits(read_exr(dir / "one.exr").rgb, read_exr(dir / "two.exr").rgb));
    // A rank that runs another subcommand.
    const ProcessResult other = run_mpmd(render_args(dir / "three.exr"), {"devices"}, dir);
    INFO("stderr: " << other.err);
    REQUIRE_FALSE(other.timed_out);
    CHECK(other.exit_code == 2);
    const std::vector<std::string> errors = lines_starting_with(other.err, "mcrt: error:");
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find("rank 1 runs mcrt devices, rank 0 mcrt render") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "three.exr"));
}
