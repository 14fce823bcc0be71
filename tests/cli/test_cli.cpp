// End-to-end tests of the mcrt executable: exit status, error lines, outputs
// (DESIGN.md "Command line", "Outputs", exit status).
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli/render_command.h"
#include "common/environment.h"
#include "image/image.h"
#include "process_support.h"
#include "render/variants.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace mcrt;
using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

// Small and fast: every render in this file uses these unless a test says otherwise.
const std::vector<std::string> kSmall = {"--width", "32", "--height", "32",
                                         "--spp",   "4",  "--quiet"};

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

std::string describe(const std::vector<std::string>& args) {
    std::string text = "mcrt";
    for (const std::string& a : args) text += " " + a;
    return text;
}

// A fresh temporary directory per test: logs at its root, outputs in out/, so out/ holds
// exactly what mcrt wrote.
struct Sandbox {
    TempDir tmp{"mcrt-cli"};
    fs::path out_dir = tmp.path() / "out";

    Sandbox() { fs::create_directory(out_dir); }

    std::string out(const std::string& name) const { return (out_dir / name).string(); }

    ProcessResult run(const std::vector<std::string>& args, double timeout_seconds = 120.0) const {
        ProcessResult r = run_process(MCRT_EXE, args, tmp.path(), timeout_seconds);
        INFO(describe(args) << "\n  exit " << r.exit_code << ", signal " << r.signal << ", "
                            << r.seconds << " s\n  stdout: " << r.out << "\n  stderr: " << r.err);
        CHECK_FALSE(r.timed_out);                // a hang
        if (!r.timed_out) CHECK(r.signal == 0);  // a crash
        return r;
    }

    std::vector<std::string> files() const {
        std::vector<std::string> names;
        for (const auto& entry : fs::recursive_directory_iterator(out_dir))
            names.push_back(entry.path().lexically_relative(out_dir).string());
        return names;
    }

    std::vector<std::string> temporary_files() const {
        std::vector<std::string> names;
        for (const std::string& name : files())
            if (name.find(".tmp") != std::string::npos) names.push_back(name);
        return names;
    }
};

std::string joined(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
    return text;
}

// Exit 2 with exactly one error line, the first line of stderr.
void check_usage_error(const ProcessResult& r) {
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(first_line(r.err).rfind("mcrt: error:", 0) == 0);
    CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
}

bool all_finite(const std::vector<float>& v) {
    for (float x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

double mean(const std::vector<float>& v) {
    double sum = 0;
    for (float x : v) sum += x;
    return v.empty() ? 0.0 : sum / double(v.size());
}

Image render_cornell(const Sandbox& box, const std::string& name,
                     const std::vector<std::string>& extra) {
    std::string exr = box.out(name);
    ProcessResult r = box.run(concat({"render", kCornell, "--out", exr}, extra));
    INFO(describe(extra) << "\nstderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    return read_exr(exr);
}

// Every .gltf / .glb under `dir`, sorted.
std::vector<fs::path> gltf_files(const fs::path& dir, bool recursive) {
    std::vector<fs::path> found;
    auto take = [&](const fs::directory_entry& e) {
        std::string ext = e.path().extension().string();
        if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb")) found.push_back(e.path());
    };
    if (recursive)
        for (const auto& e : fs::recursive_directory_iterator(dir)) take(e);
    else
        for (const auto& e : fs::directory_iterator(dir)) take(e);
    std::sort(found.begin(), found.end());
    return found;
}

// Renders `scene`: either success (exit 0, an EXR with finite pixels, no temporary left) or
// a clean rejection (exit 2, one error line naming the file, nothing written). Returns a
// one-line summary.
std::string check_robust_render(const fs::path& scene) {
    Sandbox box;
    std::string exr = box.out("r.exr");
    ProcessResult r = box.run(concat({"render", scene.string(), "--out", exr}, kSmall));
    std::vector<std::string> errors = lines_starting_with(r.err, "mcrt: error:");
    std::vector<std::string> warnings = lines_starting_with(r.err, "mcrt: warning:");
    INFO(scene.string() << "\n  exit " << r.exit_code << "\n  stderr: " << r.err);
    CHECK((r.exit_code == 0 || r.exit_code == 2));
    if (r.exit_code == 0) {
        CHECK(errors.empty());
        REQUIRE(fs::exists(exr));
        Image image = read_exr(exr);
        CHECK(image.width == 32);
        CHECK(image.height == 32);
        CHECK(all_finite(image.rgb));
        CHECK(all_finite(image.variance));
        CHECK(box.temporary_files().empty());
        return "ok (" + std::to_string(warnings.size()) + " warning(s), mean " +
               std::to_string(mean(image.rgb)) + ")";
    }
    CHECK(errors.size() == 1);
    CHECK(first_line(r.err).rfind("mcrt: error:", 0) == 0);
    if (!errors.empty()) CHECK(errors.front().find(scene.filename().string()) != std::string::npos);
    INFO("left behind: " << joined(box.files()));
    CHECK(box.files().empty());
    if (errors.empty()) return "rejected without an error line";
    std::string message = errors.front();
    size_t named = message.find(scene.filename().string() + ": ");
    return "rejected: " + (named == std::string::npos
                               ? message
                               : message.substr(named + scene.filename().string().size() + 2));
}

}  // namespace

TEST_CASE("mcrt devices lists at least one device", "[cli]") {
    Sandbox box;
    ProcessResult r = box.run({"devices"});
    INFO("stdout: " << r.out << "\nstderr: " << r.err);
    CHECK(r.exit_code == 0);
    CHECK_FALSE(lines_starting_with(r.out, "0: ").empty());
}

TEST_CASE("mcrt render writes the EXR, PNG and stats it is asked for", "[cli]") {
    Sandbox box;
    const int width = 32, height = 24, spp = 4;
    std::string exr = box.out("c.exr"), png = box.out("c.png"), stats = box.out("s.json");
    ProcessResult r = box.run({"render", kCornell, "--out", exr, "--png", png, "--stats", stats,
                               "--width", std::to_string(width), "--height", std::to_string(height),
                               "--spp", std::to_string(spp), "--quiet"});
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(lines_starting_with(r.err, "mcrt: error:").empty());

    SECTION("EXR") {
        REQUIRE(fs::exists(exr));
        Image image = read_exr(exr);
        CHECK(image.width == width);
        CHECK(image.height == height);
        CHECK(image.spp == spp);
        REQUIRE(image.rgb.size() == size_t(3 * width * height));
        REQUIRE(image.variance.size() == image.rgb.size());
        bool finite_non_negative = true;
        for (float x : image.rgb)
            finite_non_negative = finite_non_negative && std::isfinite(x) && x >= 0;
        CHECK(finite_non_negative);
        CHECK(mean(image.rgb) > 0);
        bool variance_ok = true, variance_nonzero = false;
        for (float v : image.variance) {
            variance_ok = variance_ok && std::isfinite(v) && v >= 0;
            variance_nonzero = variance_nonzero || v > 0;
        }
        CHECK(variance_ok);
        CHECK(variance_nonzero);
    }
    SECTION("PNG") {
        REQUIRE(fs::exists(png));
        CHECK(fs::file_size(png) > 8);
    }
    SECTION("stats JSON") {
        REQUIRE(fs::exists(stats));
        nlohmann::json j;
        REQUIRE_NOTHROW(j = nlohmann::json::parse(read_whole_file(stats)));
        for (const char* key : {"scene", "width", "height", "spp", "estimator", "light_select",
                                "sampler", "seed", "devices", "seconds_total", "seconds_render",
                                "samples_per_second", "rays_per_second", "nan_samples"}) {
            INFO("key " << key);
            CHECK(j.contains(key));
        }
        CHECK(j.value("width", -1) == width);
        CHECK(j.value("height", -1) == height);
        CHECK(j.value("spp", -1) == spp);
        CHECK(j.value("estimator", std::string()) == "light-area");
        CHECK(j.value("light_select", std::string()) == "power");
        CHECK(j.value("sampler", std::string()) == "independent");
        CHECK(j.value("seed", -1) == 0);
        CHECK(j.value("nan_samples", -1) == 0);
        REQUIRE(j.contains("devices"));
        REQUIRE(j["devices"].is_array());
        REQUIRE(j["devices"].size() >= 1);
        CHECK(j["devices"][0].contains("name"));
        REQUIRE(j["devices"][0].contains("samples"));
        CHECK(j["devices"][0]["samples"].get<int64_t>() == int64_t(width) * height * spp);
        CHECK(j.value("seconds_total", -1.0) >= j.value("seconds_render", -1.0));
        CHECK(j.value("samples_per_second", -1.0) > 0);
        CHECK(j.value("rays_per_second", -1.0) > 0);
    }
    SECTION("no temporary files remain") {
        INFO("files: " << joined(box.files()));
        CHECK(box.temporary_files().empty());
        CHECK(box.files().size() == 3);
    }
}

TEST_CASE("bad usage exits 2 with one error line and writes nothing", "[cli]") {
    struct Case {
        std::string name;
        std::vector<std::string> args;  // "@D" is replaced by the output directory
        std::vector<std::string> mentions;
    };
    const std::vector<std::string> out = {"--out", "@D/x.exr"};
    const std::vector<std::string> cases_scene = {"render", kCornell};
    auto render = [&](std::vector<std::string> extra) {
        return concat(concat(cases_scene, out), extra);
    };
    const std::vector<Case> cases = {
        {"unknown option", render({"--bogus"}), {"--bogus"}},
        {"unknown estimator",
         render({"--estimator", "nope"}),
         {"nope", "hemisphere-uniform", "hemisphere-cosine", "light-area", "light-solid-angle",
          "mis"}},
        {"width 0", render({"--width", "0"}), {"--width"}},
        {"width -3", render({"--width", "-3"}), {"--width"}},
        {"spp 0", render({"--spp", "0"}), {"--spp"}},
        {"spp abc", render({"--spp", "abc"}), {"--spp"}},
        {"missing --out", concat(cases_scene, {"--quiet"}), {"--out"}},
        {"no subcommand", {}, {}},
        {"--out into a missing directory",
         concat(cases_scene, {"--out", "@D/missing/x.exr"}),
         {"--out", "@D/missing"}},
        {"--png into a missing directory",
         render({"--png", "@D/missing/x.png"}),
         {"--png", "@D/missing"}},
        {"missing scene file",
         {"render", "@D/no such scene.gltf", "--out", "@D/x.exr"},
         {"no such scene.gltf"}},
        {"unknown light selection",
         render({"--light-select", "nope"}),
         {"nope", "uniform", "power", "alias"}},
        {"unknown sampler",
         render({"--sampler", "nope"}),
         {"nope", "independent", "stratified", "sobol"}},
        {"unknown MIS heuristic",
         render({"--mis-heuristic", "nope"}),
         {"nope", "balance", "power"}},
        {"camera out of range", render({"--camera", "5"}), {"--camera"}},
        {"device 99", render({"--device", "99"}), {"--device", "99"}},
        {"device bogus", render({"--device", "bogus"}), {"--device", "bogus"}},
        {"sky -1", render({"--sky", "-1"}), {"--sky"}},
        {"sky with two values", render({"--sky", "1,2"}), {"--sky"}},
        {"replicates 3", render({"--replicates", "3"}), {"--replicates", "3"}},
        {"replicates not dividing spp",
         render({"--replicates", "8", "--spp", "12"}),
         {"--replicates", "12"}},
        {"replicates 32", render({"--replicates", "32"}), {"--replicates"}},
        {"max depth beyond the bound", render({"--max-depth", "1025"}), {"--max-depth"}},
        {"max depth -1", render({"--max-depth", "-1"}), {"--max-depth"}},
        {"rr depth 0", render({"--rr-depth", "0"}), {"--rr-depth"}},
        {"ambient estimator with paths",
         render({"--estimator", "ambient-cosine", "--max-depth", "2"}),
         {"--max-depth", "ambient-cosine"}},
        {"look-from without look-at", render({"--look-from", "0,1,2"}), {"--look-at"}},
        {"look-at without look-from", render({"--look-at", "0,1,2"}), {"--look-from"}},
        {"fov without look-from", render({"--fov", "30"}), {"--look-from"}},
        {"look-from with two values",
         render({"--look-from", "0,1", "--look-at", "0,0,0"}),
         {"--look-from"}},
        {"look-from not a number",
         render({"--look-from", "a,b,c", "--look-at", "0,0,0"}),
         {"--look-from"}},
        {"look-from nan",
         render({"--look-from", "nan,0,0", "--look-at", "0,0,0"}),
         {"--look-from"}},
        {"look-from equal to look-at",
         render({"--look-from", "1,2,3", "--look-at", "1,2,3"}),
         {"--look-at", "--look-from"}},
        {"up parallel to the view",
         render({"--look-from", "0,5,0", "--look-at", "0,0,0", "--up", "0,1,0"}),
         {"--up", "parallel"}},
        {"up zero",
         render({"--look-from", "0,5,1", "--look-at", "0,0,0", "--up", "0,0,0"}),
         {"--up"}},
        {"fov 180",
         render({"--look-from", "0,1,5", "--look-at", "0,1,0", "--fov", "180"}),
         {"--fov"}},
        {"look-from with --camera",
         render({"--look-from", "0,1,5", "--look-at", "0,1,0", "--camera", "0"}),
         {"--look-from", "--camera"}},
        {"bench: up parallel to the view",
         {"bench", kCornell, "--look-from", "0,5,0", "--look-at", "0,0,0", "--width", "8",
          "--height", "8"},
         {"--up", "parallel"}},
    };
    for (const Case& c : cases) {
        Sandbox box;
        auto expand = [&](std::string s) {
            for (size_t at; (at = s.find("@D")) != std::string::npos;)
                s.replace(at, 2, box.out_dir.string());
            return s;
        };
        std::vector<std::string> args;
        for (const std::string& a : c.args) args.push_back(expand(a));
        if (!args.empty() && args[0] == "render")
            args = concat(args, {"--width", "8", "--height", "8", "--quiet"});
        ProcessResult r = box.run(args);
        INFO("case: " << c.name << "\n  " << describe(args) << "\n  stderr: " << r.err);
        check_usage_error(r);
        for (const std::string& m : c.mentions) {
            INFO("the error should mention " << expand(m));
            CHECK(r.err.find(expand(m)) != std::string::npos);
        }
        INFO("left behind: " << joined(box.files()));
        CHECK(box.files().empty());
    }
}

TEST_CASE("path tracing from the command line: depth, roulette, the sky light, a given camera",
          "[cli][paths]") {
    Sandbox box;
    const std::string exr = box.out("x.exr"), stats = box.out("x.json");
    auto run = [&](std::vector<std::string> extra) {
        ProcessResult r = box.run(
            concat(concat({"render", kCornell, "--out", exr, "--stats", stats}, kSmall), extra));
        INFO(describe(extra) << "\n  stderr: " << r.err);
        REQUIRE(r.exit_code == 0);
        return nlohmann::json::parse(read_whole_file(stats));
    };
    nlohmann::json direct = run({});
    CHECK(direct["max_depth"] == 1);
    CHECK(direct["roulette_share"] == 0.0);
    nlohmann::json paths = run({"--max-depth", "8", "--rr-depth", "2", "--estimator", "mis"});
    CHECK(paths["max_depth"] == 8);
    CHECK(paths["rr_depth"] == 2);
    CHECK(paths["roulette_share"].get<double>() > 0.0);
    CHECK(paths["mean_path_length"].get<double>() > direct["mean_path_length"].get<double>());
    CHECK(paths["rays_per_sample"].get<double>() > direct["rays_per_sample"].get<double>());
    // Indirect light adds to the box: the ceiling is no longer black.
    CHECK(paths["image_mean"][0].get<double>() > direct["image_mean"][0].get<double>());
    // The sky lights nothing inside the closed box but is seen through its open front.
    nlohmann::json sky =
        run({"--sky", "0.5", "--look-from", "0,1,6", "--look-at", "0,1,0", "--fov", "60"});
    CHECK(sky["sky_light"] == true);
    CHECK(sky["image_mean"][0].get<double>() > 0.0);
    nlohmann::json black = run({"--look-from", "0,1,6", "--look-at", "0,1,0", "--fov", "60"});
    CHECK(black["sky_light"] == false);
    CHECK(sky["image_mean"][0].get<double>() > black["image_mean"][0].get<double>());
    // bench takes the same camera.
    ProcessResult bench =
        box.run({"bench", kCornell, "--look-from", "0,1,6", "--look-at", "0,1,0", "--width", "16",
                 "--height", "16", "--rays", "primary", "--repeats", "1"});
    INFO(bench.err);
    CHECK(bench.exit_code == 0);
    CHECK(bench.out.find("--look-from") != std::string::npos);
}

TEST_CASE("every estimator, light selection and sampler renders from the command line", "[cli]") {
    // The names as `mcrt variants --json` lists them: what the scripts read.
    Sandbox listing;
    ProcessResult listed = listing.run({"variants", "--json"});
    REQUIRE(listed.exit_code == 0);
    nlohmann::json table = nlohmann::json::parse(listed.out);
    REQUIRE(table["estimators"].size() == kEstimatorVariants.size());
    std::vector<std::string> estimators, selections, samplers;
    for (const auto& row : table["estimators"]) estimators.push_back(row["name"]);
    for (const auto& row : table["light_select"]) selections.push_back(row["name"]);
    for (const auto& row : table["samplers"]) samplers.push_back(row["name"]);
    CHECK(estimators == variant_names(kEstimatorVariants));
    CHECK(selections == variant_names(kLightSelectVariants));
    CHECK(samplers == variant_names(kSamplerVariants));
    // Every name once; the combinations are the estimator tests' job.
    std::vector<std::array<std::string, 3>> runs;
    for (const std::string& e : estimators) runs.push_back({e, "power", "independent"});
    for (const std::string& l : selections) runs.push_back({"light-area", l, "independent"});
    for (const std::string& g : samplers) runs.push_back({"light-area", "power", g});
    for (const auto& [estimator, select, sampler] : runs) {
        Sandbox box;
        ProcessResult r =
            box.run(concat({"render", kCornell, "--out", box.out("x.exr"), "--estimator", estimator,
                            "--light-select", select, "--sampler", sampler},
                           kSmall));
        INFO(estimator << " / " << select << " / " << sampler << "\n  stderr: " << r.err);
        REQUIRE(r.exit_code == 0);
        Image img = read_exr(box.out("x.exr"));
        double sum = 0;
        for (float v : img.rgb) {
            REQUIRE(std::isfinite(v));
            sum += v;
        }
        CHECK(sum > 0);
    }
}

TEST_CASE("a rejected render leaves an existing output untouched", "[cli]") {
    Sandbox box;
    std::string exr = box.out("x.exr");
    std::ofstream(exr) << "keep";
    ProcessResult r = box.run(concat(
        {"render", std::string(MCRT_TEST_DATA) + "/nan_position.gltf", "--out", exr}, kSmall));
    check_usage_error(r);
    CHECK(read_whole_file(exr) == "keep");
    INFO("files: " << joined(box.files()));
    CHECK(box.files().size() == 1);
}

TEST_CASE("output paths with spaces reach mcrt intact", "[cli]") {
    Sandbox box;
    fs::create_directory(box.out_dir / "with space");
    std::string exr = box.out("with space/c d.exr"), png = box.out("with space/c d.png");
    ProcessResult r = box.run(concat({"render", kCornell, "--out", exr, "--png", png}, kSmall));
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 0);
    CHECK(fs::exists(exr));
    CHECK(fs::exists(png));
}

// DESIGN.md: "a value out of range" exits 2. CLI11's Range check compares with < and >, which
// NaN passes; cli.cpp adds a finiteness check, tested here for each floating-point option.
TEST_CASE("NaN option values are rejected", "[cli]") {
    for (const char* option : {"--exposure", "--ao-distance", "--time-limit"}) {
        Sandbox box;
        ProcessResult r = box.run(concat({"render", kCornell, "--out", box.out("x.exr"), "--png",
                                          box.out("x.png"), option, "nan"},
                                         kSmall));
        INFO(option << " nan\n  stderr: " << r.err);
        check_usage_error(r);
        CHECK(r.err.find(option) != std::string::npos);
        INFO("left behind: " << joined(box.files()));
        CHECK(box.files().empty());
    }
}

// A number's refusal says why: a denormal (4.9e-324) is finite and accepted; a value that rounds
// to 0 or overflows double is refused as such, not called "not a finite number".
TEST_CASE("floating-point option values are refused with their true reason", "[cli]") {
    const std::pair<const char*, const char*> refused[] = {
        {"1e-400", "'1e-400' is too small to tell from 0"},
        {"1e400", "'1e400' is beyond the largest finite number"},
        {"inf", "'inf' is not a finite number"},
        {"12s", "'12s' is not a number"}};
    for (const auto& [value, said] : refused) {
        Sandbox box;
        ProcessResult r = box.run(
            concat({"render", kCornell, "--out", box.out("x.exr"), "--time-limit", value}, kSmall));
        INFO(value << "\n  stderr: " << r.err);
        check_usage_error(r);
        CHECK(r.err.find(std::string("--time-limit: ") + said) != std::string::npos);
        CHECK(box.files().empty());
    }
    // A float option too: an --ao-distance that rounds to 0 in float would be "unbounded".
    {
        Sandbox box;
        ProcessResult r =
            box.run(concat({"render", kCornell, "--out", box.out("x.exr"), "--estimator",
                            "ambient-uniform", "--ao-distance", "1e-50"},
                           kSmall));
        INFO(r.err);
        check_usage_error(r);
        CHECK(r.err.find("--ao-distance: '1e-50' is too small to tell from 0 (the smallest is "
                         "1.4e-45)") != std::string::npos);
        CHECK(box.files().empty());
    }
    // A sky radiance below float's smallest is in [0, 1e30] (it rounds as any float does); a
    // trailing comma is no value.
    {
        Sandbox box;
        ProcessResult tiny = box.run(concat({"render", kCornell, "--out", box.out("x.exr"),
                                             "--estimator", "ambient-uniform", "--sky", "1e-50"},
                                            kSmall));
        INFO(tiny.err);
        CHECK(tiny.exit_code == 0);
        ProcessResult comma =
            box.run(concat({"render", kCornell, "--out", box.out("y.exr"), "--sky", "1,"}, kSmall));
        INFO(comma.err);
        check_usage_error(comma);
        CHECK(comma.err.find("--sky 1,: expected R,G,B or one value") != std::string::npos);
    }
    // The smallest positive double is a time limit: the render stops at its first check, with
    // its first chunk row (the supervisor is told the limit with every digit, not "0.000000").
    Sandbox box;
    const std::string exr = box.out("t.exr"), stats = box.out("t.json");
    ProcessResult r =
        box.run({"render", kCornell, "--out", exr, "--stats", stats, "--width", "16", "--height",
                 "16", "--spp", "65536", "--quiet", "--time-limit", "4.9e-324"});
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json j = nlohmann::json::parse(read_whole_file(stats));
    CHECK(j["stopped_by"] == "time limit");
    CHECK(j["spp"].get<int>() < 65536);
    CHECK(j["spp"].get<int>() >= 16);
}

TEST_CASE("broken and valid glTF files in tests/data render or are rejected cleanly",
          "[cli][robustness]") {
    std::vector<fs::path> files = gltf_files(MCRT_TEST_DATA, false);
    REQUIRE_FALSE(files.empty());
    std::string summary;
    for (const fs::path& f : files)
        summary += "\n  " + f.filename().string() + ": " + check_robust_render(f);
    WARN("tests/data:" << summary);
}

TEST_CASE("the robustness and Khronos scenes render or are rejected cleanly", "[cli][robustness]") {
    const fs::path scenes = MCRT_SCENES;
    std::vector<fs::path> files;
    for (const char* sub : {"robustness", "khronos"})
        for (const fs::path& f : gltf_files(scenes / sub, true)) files.push_back(f);
    REQUIRE(files.size() >= 12);
    std::string summary;
    for (const fs::path& f : files)
        summary += "\n  " + f.lexically_relative(scenes).string() + ": " + check_robust_render(f);
    WARN("scenes/robustness and scenes/khronos:" << summary);
}

TEST_CASE("mcrt render --help lists the options and their defaults", "[cli]") {
    Sandbox box;
    ProcessResult r = box.run({"render", "--help"});
    INFO("stdout: " << r.out << "\nstderr: " << r.err);
    CHECK(r.exit_code == 0);
    for (const char* text :
         {"--estimator", "--out", "--spp", "512", "16", "light-area", "power", "independent"}) {
        INFO("help should mention " << text);
        CHECK(r.out.find(text) != std::string::npos);
    }
    CHECK(box.files().empty());
}

TEST_CASE("renders are deterministic end to end", "[cli][determinism]") {
    Sandbox box;
    SECTION("the same render twice") {
        Image a = render_cornell(box, "a.exr", kSmall);
        Image b = render_cornell(box, "b.exr", kSmall);
        CHECK(same_bits(a.rgb, b.rgb));
        CHECK(same_bits(a.variance, b.variance));
    }
    SECTION("batch size does not change the image") {
        const std::vector<std::string> common = {"--width", "32", "--height", "32",
                                                 "--spp",   "40", "--quiet"};
        Image a = render_cornell(box, "a.exr", concat(common, {"--batch", "16"}));
        Image b = render_cornell(box, "b.exr", concat(common, {"--batch", "48"}));
        Image c = render_cornell(box, "c.exr", concat(common, {"--batch", "1"}));
        CHECK(a.spp == 40);
        CHECK(b.spp == 40);
        CHECK(same_bits(a.rgb, b.rgb));
        CHECK(same_bits(a.variance, b.variance));
        CHECK(same_bits(a.rgb, c.rgb));
        CHECK(same_bits(a.variance, c.variance));
    }
    SECTION("the seed changes the image") {
        Image a = render_cornell(box, "a.exr", concat(kSmall, {"--seed", "1"}));
        Image b = render_cornell(box, "b.exr", concat(kSmall, {"--seed", "2"}));
        CHECK_FALSE(same_bits(a.rgb, b.rgb));
    }
}

TEST_CASE("a scene without emitters renders black with a warning", "[cli][shared]") {
    std::string scene = scene_path("khronos/Box/Box.gltf");
    Sandbox box;
    std::string exr = box.out("b.exr");
    ProcessResult r = box.run(concat({"render", scene, "--out", exr}, kSmall));
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    std::vector<std::string> warnings = lines_starting_with(r.err, "mcrt: warning:");
    bool mentions_emissive = false;
    for (const std::string& w : warnings)
        mentions_emissive = mentions_emissive || w.find("emissive") != std::string::npos;
    CHECK(mentions_emissive);
    Image image = read_exr(exr);
    bool black = true;
    for (float x : image.rgb) black = black && x == 0.0f;
    CHECK(black);
    CHECK(box.temporary_files().empty());
}

TEST_CASE("a scene without a camera renders with the bench camera", "[cli][shared]") {
    SECTION("khronos Box (no camera, no emitter)") {
        std::string scene = scene_path("khronos/Box/Box.gltf");
        nlohmann::json gltf = nlohmann::json::parse(read_whole_file(scene));
        REQUIRE((!gltf.contains("cameras") || gltf["cameras"].empty()));
        Sandbox box;
        ProcessResult r = box.run(concat({"render", scene, "--out", box.out("b.exr")}, kSmall));
        INFO("stderr: " << r.err);
        CHECK(r.exit_code == 0);
        CHECK(fs::exists(box.out("b.exr")));
    }
    SECTION("an emissive floor seen by the bench camera") {
        // A 40×40 double-sided emitter (L_e = 1) in the plane y = -1.05, no camera: the bench
        // camera looks down at its centre from c + diag·(0.35, 0.30, 0.55), 45° field of view,
        // so the centre pixel sees L_e (light from a coplanar emitter adds nothing) while the
        // top row looks past the floor's far edge into black.
        std::string scene = scene_path("cornell-fazil47/emissive_floor.glb");
        Sandbox box;
        std::string exr = box.out("f.exr");
        ProcessResult r = box.run(concat({"render", scene, "--out", exr}, kSmall));
        INFO("stderr: " << r.err);
        REQUIRE(r.exit_code == 0);
        Image image = read_exr(exr);
        REQUIRE(image.width == 32);
        auto red = [&](int i, int j) { return image.rgb[3 * (size_t(j) * image.width + i)]; };
        CHECK(red(16, 16) == Approx(1.0f).epsilon(1e-3));
        CHECK(red(0, 0) == 0.0f);
        CHECK(red(31, 0) == 0.0f);
    }
}

TEST_CASE("the Stanford bunny (.glb, no camera) renders with the bench camera", "[cli][extended]") {
    std::string scene = extended_scene("stanford/bunny_zipper.glb");
    Sandbox box;
    ProcessResult r = box.run(concat({"render", scene, "--out", box.out("b.exr")}, kSmall));
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 0);
    CHECK(fs::exists(box.out("b.exr")));
}

TEST_CASE("the EXR and the stats say which variance estimate the layer holds", "[cli][variance]") {
    for (const auto& [sampler, replicates, spp] :
         {std::make_tuple("independent", "1", "16"), std::make_tuple("sobol", "2", "16"),
          std::make_tuple("sobol", "2", "6"), std::make_tuple("stratified", "1", "1")}) {
        Sandbox box;
        ProcessResult r = box.run({"render", kCornell, "--out", box.out("x.exr"), "--stats",
                                   box.out("x.json"), "--sampler", sampler, "--spp", spp, "--width",
                                   "16", "--height", "16", "--quiet"});
        INFO(sampler << ", spp " << spp << ": " << r.err);
        REQUIRE(r.exit_code == 0);
        std::ifstream in(box.out("x.json"));
        nlohmann::json j = nlohmann::json::parse(in);
        CHECK(std::to_string(j["replicates"].get<int>()) == replicates);
        CHECK(j["variance_estimate"] ==
              (std::string(replicates) == "1" ? "samples" : "replicates"));
        std::ifstream exr(box.out("x.exr"), std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(exr)), std::istreambuf_iterator<char>());
        CHECK(bytes.find("mcrt.replicates") != std::string::npos);
        CHECK(bytes.find(std::string(replicates) == "1"
                             ? "the samples' variance over their number"
                             : "independent replicate means") != std::string::npos);
    }
}

TEST_CASE("every environment variable mcrt reads is read through one table and documented",
          "[cli]") {
    namespace fs = std::filesystem;
    const fs::path root = MCRT_SOURCE_DIR;
    auto text_of = [](const fs::path& p) {
        std::ifstream in(p);
        std::stringstream s;
        s << in.rdbuf();
        return s.str();
    };
    // The table is in enum order, one row per variable.
    REQUIRE(mcrt::kEnvironment.size() == size_t(mcrt::kEnvironmentVariableCount));
    for (size_t i = 0; i < mcrt::kEnvironment.size(); ++i)
        CHECK(size_t(mcrt::kEnvironment[i].id) == i);
    // No source file reads the environment but common/environment.cpp.
    for (const auto& entry : fs::recursive_directory_iterator(root / "host")) {
        if (!entry.is_regular_file() || entry.path().filename() == "environment.cpp") continue;
        INFO(entry.path().string());
        CHECK(text_of(entry.path()).find("getenv(") == std::string::npos);
    }
    // docs/DESIGN.md has a line for each.
    const std::string design = text_of(root / "docs" / "DESIGN.md");
    for (const mcrt::EnvironmentEntry& e : mcrt::kEnvironment) {
        INFO(e.name);
        CHECK(design.find(std::string("`") + e.name + "`") != std::string::npos);
    }
}

TEST_CASE("an empty value is refused for every option of every subcommand", "[cli][empty]") {
    // The options are read from each subcommand's --help ("--name TYPE"), so one added later is
    // covered too; the scene positional as well.
    Sandbox help_box;
    for (const std::string command : {"render", "bench", "integrate"}) {
        const ProcessResult help = help_box.run({command, "--help"});
        REQUIRE(help.exit_code == 0);
        std::vector<std::string> options;
        std::istringstream lines(help.out);
        for (std::string line; std::getline(lines, line);) {
            std::istringstream words(line);
            std::string name, type;
            words >> name >> type;
            type = type.substr(0, type.find_first_of(":="));  // "INT:INT in [1 - 16384]=1024"
            if (name.rfind("--", 0) == 0 && !type.empty() &&
                type.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ") == std::string::npos)
                options.push_back(name);
        }
        CHECK(options.size() >= (command == "render" ? 20u : 5u));
        if (command != "integrate") options.push_back("scene");
        for (const std::string& option : options) {
            Sandbox box;
            std::vector<std::string> args = {command};
            if (command != "integrate") args.push_back(option == "scene" ? "" : kCornell);
            if (command == "render" && option != "--out")
                args = concat(args, {"--out", box.out("x.exr")});
            if (option != "scene") args = concat(args, {option, ""});
            ProcessResult r = box.run(args, 60);
            INFO(describe(args) << "\n  stderr: " << r.err);
            check_usage_error(r);
            CHECK(r.err.find(option == "scene" ? "scene" : option + ":") != std::string::npos);
            CHECK(r.seconds < 20);  // refused while parsing, not after a render
            CHECK(box.files().empty());
        }
    }
}

TEST_CASE("non-finite samples are counted, warned about, and an image of nothing else is refused",
          "[cli][nonfinite][estimator-file]") {
    Sandbox box;
    auto estimator = [&](const std::string& name, const std::string& value) {
        const std::string path = (box.tmp.path() / name).string();
        std::ofstream(path) << "float3 estimate(const SceneView* scene, const SurfacePoint* sp, "
                               "const SampleStream* stream, uint* rays) {\n"
                               "    return "
                            << value << ";\n}\n";
        return path;
    };
    const std::vector<std::string> size = {"--width", "16", "--height", "12",
                                           "--spp",   "16", "--quiet"};
    SECTION("some samples: one warning with their count and share, the count in the stats") {
        // Infinite on the surfaces facing +x (the left wall), NaN nowhere else.
        const std::string file =
            estimator("some.cl", "sp->n.x > 0.5f ? (float3)(1.0f / 0.0f) : (float3)(0.5f)");
        ProcessResult r = box.run(concat({"render", kCornell, "--out", box.out("a.exr"), "--stats",
                                          box.out("a.json"), "--estimator-file", file},
                                         size));
        REQUIRE(r.exit_code == 0);
        const auto warnings = lines_starting_with(r.err, "mcrt: warning:");
        REQUIRE(warnings.size() == 1);
        const auto stats = nlohmann::json::parse(read_whole_file(box.out("a.json")));
        const uint64_t bad = stats["nan_samples"];
        CHECK(bad > 0);
        CHECK(bad < 16 * 12 * 16);
        char share[16];
        std::snprintf(share, sizeof share, "%.1f%%", 100.0 * double(bad) / (16 * 12 * 16));
        CHECK(warnings[0] == "mcrt: warning: " + std::to_string(bad) + " of 3072 samples (" +
                                 share +
                                 ") were not finite (NaN or infinite) and were counted as 0");
        CHECK(all_finite(read_exr(box.out("a.exr")).rgb));
    }
    SECTION("no non-finite sample: no warning") {
        ProcessResult r = box.run(
            concat({"render", kCornell, "--out", box.out("a.exr"), "--stats", box.out("a.json"),
                    "--estimator-file", estimator("fine.cl", "(float3)(0.5f)")},
                   size));
        REQUIRE(r.exit_code == 0);
        CHECK(lines_starting_with(r.err, "mcrt: warning:").empty());
        CHECK(nlohmann::json::parse(read_whole_file(box.out("a.json")))["nan_samples"] == 0);
    }
    SECTION("every sample: exit 1, one error line, nothing written") {
        // Inside the box looking at the back wall: every camera ray meets a surface.
        for (const std::string value : {"(float3)(NAN)", "(float3)(1.0f / 0.0f)"}) {
            ProcessResult r = box.run(concat(
                {"render", kCornell, "--out", box.out("a.exr"), "--png", box.out("a.png"),
                 "--stats", box.out("a.json"), "--estimator-file", estimator("all.cl", value),
                 "--look-from", "0,1,0", "--look-at", "0,1,-1", "--fov", "40"},
                size));
            INFO(value << ": " << r.err);
            CHECK(r.exit_code == 1);
            CHECK(lines_starting_with(r.err, "mcrt: error:").size() == 1);
            CHECK(r.err.find("all 3072 samples were not finite") != std::string::npos);
            CHECK(box.files().empty());
        }
    }
}

TEST_CASE("every render option but --device is in the words the MPI ranks compare", "[cli][mpi]") {
    // render_option_words is what rank 0 compares every rank's command line against
    // (agree_on_command): an option left out of it would let a rank render with its own.
    CLI::App app;
    RenderOptions o;
    CLI::App* render = add_render_command(app, o);
    const std::vector<std::string> words = render_option_words(o);
    size_t checked = 0;
    for (const CLI::Option* option : render->get_options()) {
        std::string name = option->get_name();
        if (name == "--help" || name == "--device") continue;
        if (name.rfind("--", 0) != 0) name = "the " + name;  // the scene positional
        INFO(name);
        const bool found = std::any_of(words.begin(), words.end(), [&](const std::string& w) {
            return w == name || w == "no " + name || w.rfind(name + " ", 0) == 0;
        });
        CHECK(found);
        ++checked;
    }
    CHECK(checked >= 25);
    CHECK(words.size() == checked);  // one word per option, none twice
}
