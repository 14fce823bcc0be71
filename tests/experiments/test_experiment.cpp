// The experiment harness (scripts/experiments/experiment.py) in its quick mode, end to end: on the
// Cornell box (one small light) it writes results.csv with a row per (configuration, spp), the four
// charts, and ranks light-area above hemisphere-cosine in efficiency, while the error of every
// configuration falls as spp grows. Skipped when Debian's python3 with numpy and matplotlib is
// missing.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"

using namespace mcrt::test;

namespace {

const char* kPython = "/usr/bin/python3";

std::string script_path() {
    return (std::filesystem::path(MCRT_SCENES).parent_path() / "scripts" / "experiments" /
            "experiment.py")
        .string();
}

void require_python_modules(const std::filesystem::path& scratch) {
    if (!std::filesystem::exists(kPython)) skip_test(std::string(kPython) + " not found");
    ProcessResult probe = run_process(kPython, {"-c", "import numpy, matplotlib"}, scratch, 60.0);
    if (probe.exit_code != 0)
        skip_test("python3 lacks numpy or matplotlib: " + first_line(probe.err));
}

std::vector<std::string> split(const std::string& line, char separator) {
    std::vector<std::string> fields;
    std::stringstream in(line);
    std::string field;
    while (std::getline(in, field, separator)) fields.push_back(field);
    return fields;
}

// results.csv as rows of column name → text.
std::vector<std::map<std::string, std::string>> read_csv(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    std::vector<std::map<std::string, std::string>> rows;
    if (!std::getline(in, line)) return rows;
    std::vector<std::string> header = split(line, ',');
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        std::vector<std::string> fields = split(line, ',');
        std::map<std::string, std::string> row;
        for (size_t i = 0; i < header.size() && i < fields.size(); ++i) row[header[i]] = fields[i];
        rows.push_back(row);
    }
    return rows;
}

}  // namespace

TEST_CASE("experiment harness, quick mode: CSV, charts, light-area beats hemisphere-cosine",
          "[experiment][e2e]") {
    TempDir scratch("mcrt-experiment");
    require_python_modules(scratch.path());

    std::string out = scratch / "out";
    ProcessResult run =
        run_process(kPython,
                    {script_path(), std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf",
                     "--estimators", "light-area,hemisphere-cosine", "--spp", "4,16,64", "--quick",
                     "--reference", "auto", "--reference-cache", scratch / "references", "--mcrt",
                     MCRT_EXE, "--out", out},
                    scratch.path(), 180.0);
    INFO("stderr: " << run.err);
    REQUIRE_FALSE(run.timed_out);
    REQUIRE(run.exit_code == 0);
    WARN("experiment.py --quick took " << run.seconds << " s");

    // The CSV: the required columns, one row per estimator × spp.
    auto rows = read_csv(out + "/results.csv");
    REQUIRE(rows.size() == 6);
    for (const char* column :
         {"estimator", "light_select", "sampler", "spp", "seconds", "rmse", "relmse", "efficiency",
          "wall_seconds", "repeat", "reference_rmse_floor"})
        REQUIRE(rows[0].count(column) == 1);

    // The charts exist and are PNGs.
    for (const char* chart :
         {"error_vs_time.png", "error_vs_spp.png", "efficiency.png", "equal_time.png"}) {
        std::string path = out + "/" + chart;
        INFO(path);
        REQUIRE(std::filesystem::exists(path));
        REQUIRE(std::filesystem::file_size(path) > 1000);
        REQUIRE(read_whole_file(path).substr(1, 3) == "PNG");
    }

    // The equal-time renders: one line per configuration after the header.
    std::string equal_time = read_whole_file(out + "/equal_time.csv");
    REQUIRE(lines_starting_with(equal_time, "light-area,").size() == 1);
    REQUIRE(lines_starting_with(equal_time, "hemisphere-cosine,").size() == 1);

    // The error of each configuration falls as spp grows (4 → 16 → 64: ×4 samples per step,
    // RMSE ÷2 expected; the reference's own floor is far below).
    std::map<std::string, std::map<int, std::map<std::string, double>>> by_config;
    for (auto& r : rows)
        by_config[r["estimator"]][std::stoi(r["spp"])] = {
            {"rmse", std::stod(r["rmse"])},
            {"relmse", std::stod(r["relmse"])},
            {"efficiency", std::stod(r["efficiency"])},
            {"floor", std::stod(r["reference_rmse_floor"])}};
    REQUIRE(by_config.size() == 2);
    for (auto& [estimator, levels] : by_config) {
        INFO(estimator);
        REQUIRE(levels.size() == 3);
        REQUIRE(levels[16]["rmse"] < levels[4]["rmse"]);
        REQUIRE(levels[64]["rmse"] < levels[16]["rmse"]);
        REQUIRE(levels[64]["relmse"] < levels[16]["relmse"]);
        REQUIRE(levels[16]["relmse"] < levels[4]["relmse"]);
        REQUIRE(levels[64]["floor"] < 0.5 * levels[64]["rmse"]);
    }

    // Light sampling wins on a scene lit by one small light: higher efficiency, compared as the
    // geometric mean over the three levels (kernel times of 1–100 ms are noisy on a busy machine).
    auto geometric_mean_efficiency = [&](const std::string& estimator) {
        double log_sum = 0;
        for (auto& [spp, m] : by_config[estimator]) log_sum += std::log(m["efficiency"]);
        return std::exp(log_sum / 3);
    };
    double area = geometric_mean_efficiency("light-area");
    double cosine = geometric_mean_efficiency("hemisphere-cosine");
    INFO("efficiency light-area " << area << ", hemisphere-cosine " << cosine);
    REQUIRE(area > cosine);
}

// --render-options reaches every render and the auto reference, through the Python module and
// through `mcrt render` commands alike: the sun map through the Cornell box's open front adds
// light to the reference and to the renders, the reference's cache key changes with it, and the
// two render paths agree on every error.
TEST_CASE("experiment harness: --render-options --env reaches the reference and the renders",
          "[experiment][e2e]") {
    TempDir scratch("mcrt-experiment-env");
    require_python_modules(scratch.path());
    ProcessResult maps = run_process(
        kPython,
        {std::string(MCRT_SOURCE_DIR) + "/scripts/scenes/make_sky_maps.py", scratch / "sky"},
        scratch.path(), 120.0);
    INFO("make_sky_maps.py: " << maps.err);
    REQUIRE(maps.exit_code == 0);
    std::string map = scratch / "sky/sun-sky.hdr";

    auto run = [&](const std::string& name, std::vector<std::string> more) {
        std::vector<std::string> arguments = {
            script_path(),
            std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf",
            "--estimators",
            "light-area",
            "--spp",
            "4",
            "--quick",
            "--reference-spp",
            "16",
            "--materials",
            "lambert",
            "--reference-cache",
            scratch / "references",
            "--mcrt",
            MCRT_EXE,
            "--out",
            scratch / name};
        arguments.insert(arguments.end(), more.begin(), more.end());
        ProcessResult done = run_process(kPython, arguments, scratch.path(), 180.0);
        INFO(name << " stderr: " << done.err);
        REQUIRE_FALSE(done.timed_out);
        REQUIRE(done.exit_code == 0);
        auto rows = read_csv(scratch / (name + "/results.csv"));
        REQUIRE(rows.size() == 1);
        return std::make_pair(rows[0], read_whole_file(scratch / (name + "/reference.json")));
    };
    // The reference's image mean, from its provenance JSON.
    auto reference_mean = [](const std::string& json) {
        size_t at = json.find("\"image_mean\": ");
        REQUIRE(at != std::string::npos);
        return std::stod(json.substr(at + 14));
    };

    auto [plain, plain_json] = run("plain", {});
    std::string options = "--env " + map + " --env-rotate 200";
    auto [module, module_json] = run("env", {"--render-options", options});
    auto [cli, cli_json] = run("env-cli", {"--render-options", options, "--cli"});

    REQUIRE(plain_json.find("render_options") == std::string::npos);
    REQUIRE(module_json.find("\"render_options\"") != std::string::npos);
    REQUIRE(module_json.find("sun-sky.hdr") != std::string::npos);
    // The sun through the open front: more light in the reference and in the render.
    double plain_mean = reference_mean(plain_json), env_mean = reference_mean(module_json);
    INFO("reference means: " << plain_mean << " without the map, " << env_mean << " with it");
    REQUIRE(env_mean > 1.05 * plain_mean);
    REQUIRE(std::stod(module["image_mean"]) > 1.05 * std::stod(plain["image_mean"]));
    // The module and the commands: the same images, so the same errors against the same
    // (cached) reference.
    REQUIRE(reference_mean(cli_json) == env_mean);
    REQUIRE(cli["rmse"] == module["rmse"]);
    REQUIRE(cli["image_mean"] == module["image_mean"]);
}
