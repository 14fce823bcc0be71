// `mcrt bench` in its quick mode (a small scene, 64×64, two repeats): the JSON lines and their
// counts, and agreement with Embree's hit counts when it is compiled in. Not a timed test: speed
// is never asserted, only that a rate was measured.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "process_support.h"

using namespace mcrt::test;

namespace {

const std::string kCornell = std::string(MCRT_SCENES) + "/cornell/CornellBox-Original.gltf";

ProcessResult run_bench(const std::vector<std::string>& args) {
    TempDir tmp{"mcrt-bench"};
    std::vector<std::string> full = {"bench"};
    full.insert(full.end(), args.begin(), args.end());
    return run_process(MCRT_EXE, full, tmp.path(), 300.0);
}

// Every stdout line parsed as JSON, keyed by its "rays" kind.
std::map<std::string, nlohmann::json> parse_lines(const std::string& out) {
    std::map<std::string, nlohmann::json> by_kind;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
        INFO(line);
        nlohmann::json j;
        REQUIRE_NOTHROW(j = nlohmann::json::parse(line));
        REQUIRE(j.is_object());
        REQUIRE(j.contains("rays"));
        by_kind[j["rays"].get<std::string>()] = j;
    }
    return by_kind;
}

}  // namespace

TEST_CASE("bench --json prints one consistent line per ray kind", "[bench]") {
    ProcessResult r =
        run_bench({kCornell, "--width", "64", "--height", "64", "--repeats", "2", "--json"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    auto lines = parse_lines(r.out);
    REQUIRE(lines.size() == 3);
    REQUIRE(lines.count("primary") == 1);
    REQUIRE(lines.count("shadow") == 1);
    REQUIRE(lines.count("ambient") == 1);

    for (const auto& [kind, j] : lines) {
        INFO(kind << ": " << j.dump());
        for (const char* key : {"scene", "rays", "count", "hits", "mrays_per_s", "seconds_median",
                                "bvh_build_seconds", "sah_cost", "bvh_depth", "bvh_nodes",
                                "bvh_packets", "triangles", "bytes_per_triangle"})
            REQUIRE(j.contains(key));
        // A packet holds one to four triangles of one leaf.
        const long long triangles = j["triangles"], packets = j["bvh_packets"];
        CHECK(packets >= (triangles + 3) / 4);
        CHECK(packets <= triangles);
        CHECK(j["bvh_depth"].get<int>() >= 1);
        CHECK(j["bvh_nodes"].get<long long>() >= 1);
        CHECK(j["scene"] == kCornell);
        CHECK(j["hits"].get<long long>() >= 0);
        CHECK(j["hits"].get<long long>() <= j["count"].get<long long>());
        CHECK(j["mrays_per_s"].get<double>() > 0.0);
        CHECK(j["seconds_median"].get<double>() > 0.0);
        CHECK(j["sah_cost"].get<double>() > 0.0);
        CHECK(j["bytes_per_triangle"].get<double>() > 0.0);
#ifdef MCRT_HAVE_EMBREE
        for (const char* key : {"embree_mrays_per_s", "embree_hits", "hit_mismatches"})
            REQUIRE(j.contains(key));
        CHECK(j["embree_mrays_per_s"].get<double>() > 0.0);
        CHECK(j["embree_hits"].get<long long>() <= j["count"].get<long long>());
#endif
    }

    // One ray per pixel; one shadow and four ambient rays per primary hit.
    long long primary_hits = lines["primary"]["hits"];
    CHECK(lines["primary"]["count"] == 64 * 64);
    CHECK(primary_hits > 0);
    CHECK(lines["shadow"]["count"] == primary_hits);
    CHECK(lines["ambient"]["count"] == 4 * primary_hits);

#ifdef MCRT_HAVE_EMBREE
    // Embree's single-ray intersector is not watertight: allow 1 in 10,000.
    long long count = lines["primary"]["count"];
    long long mismatches = lines["primary"]["hit_mismatches"];
    CHECK(mismatches <= count / 10000 + 2);
    CHECK(std::llabs(lines["primary"]["embree_hits"].get<long long>() - primary_hits) <=
          mismatches);
#endif
}

TEST_CASE("bench --rays runs one kind; the table is the default output", "[bench]") {
    ProcessResult json = run_bench({kCornell, "--rays", "ambient", "--width", "32", "--height",
                                    "16", "--repeats", "1", "--json"});
    INFO(json.err);
    REQUIRE(json.exit_code == 0);
    auto lines = parse_lines(json.out);
    REQUIRE(lines.size() == 1);
    REQUIRE(lines.count("ambient") == 1);
    CHECK(lines["ambient"]["count"].get<long long>() % 4 == 0);

    ProcessResult table =
        run_bench({kCornell, "--width", "32", "--height", "32", "--repeats", "1"});
    INFO(table.err);
    REQUIRE(table.exit_code == 0);
    CHECK(table.out.find("primary") != std::string::npos);
    CHECK(table.out.find("shadow") != std::string::npos);
    CHECK(table.out.find("ambient") != std::string::npos);
    CHECK(table.out.find("Mrays/s") != std::string::npos);
}

TEST_CASE("bench --bvh-max-leaf and --bvh-traversal-cost shape the tree, not the hits", "[bench]") {
    auto primary = [](std::vector<std::string> extra) {
        std::vector<std::string> args = {kCornell,   "--rays", "primary",   "--width", "48",
                                         "--height", "48",     "--repeats", "1",       "--json"};
        args.insert(args.end(), extra.begin(), extra.end());
        ProcessResult r = run_bench(args);
        INFO(r.err);
        REQUIRE(r.exit_code == 0);
        auto lines = parse_lines(r.out);
        REQUIRE(lines.count("primary") == 1);
        return lines["primary"];
    };
    const auto standard = primary({});
    const auto single = primary({"--bvh-max-leaf", "1"});
    const auto free_nodes = primary({"--bvh-traversal-cost", "0"});
    // Leaves of one triangle: a packet per triangle, one lane used in each.
    CHECK(single["bvh_packets"] == single["triangles"]);
    // The default fills the box's 36 triangles into the fewest packets, 9; node visits priced
    // at nothing split wherever the SAH does not lose, so more, emptier packets and more nodes.
    CHECK(standard["bvh_packets"] == 9);
    CHECK(free_nodes["bvh_packets"].get<long long>() > standard["bvh_packets"].get<long long>());
    CHECK(free_nodes["bvh_nodes"].get<long long>() > standard["bvh_nodes"].get<long long>());
    CHECK(single["hits"] == standard["hits"]);
    CHECK(free_nodes["hits"] == standard["hits"]);
#ifdef MCRT_HAVE_EMBREE
    // Leaves of one triangle resolve the box's coplanar triangles (its light and ceiling) in
    // another order than Embree: other triangles, but always at Embree's distance.
    for (const auto* j : {&standard, &single, &free_nodes}) {
        REQUIRE(j->contains("triangle_mismatches_apart"));
        CHECK((*j)["triangle_mismatches_apart"] == 0);
        CHECK((*j)["triangle_mismatches_apart"].get<long long>() <=
              (*j)["triangle_mismatches"].get<long long>());
    }
#endif
}

TEST_CASE("bench rejects bad input with exit status 2", "[bench]") {
    const std::vector<std::vector<std::string>> bad = {
        {kCornell, "--rays", "diffuse"},
        {kCornell, "--width", "0"},
        {kCornell, "--height", "16385"},
        {kCornell, "--repeats", "0"},
        {kCornell, "--repeats", "1001"},
        {kCornell, "--device", "999"},
        {kCornell, "--bogus"},
        {kCornell, "--bvh-max-leaf", "0"},
        {kCornell, "--bvh-traversal-cost", "nan"},
        {kCornell, "--bvh-traversal-cost", "-1"},
        {std::string(MCRT_SCENES) + "/no-such-scene.gltf"},
        {},
    };
    for (const auto& args : bad) {
        ProcessResult r = run_bench(args);
        std::string joined;
        for (const std::string& a : args) joined += a + " ";
        INFO("mcrt bench " << joined << "\n" << r.err);
        CHECK(r.exit_code == 2);
        CHECK(r.err.rfind("mcrt: error: ", 0) == 0);
        CHECK(r.out.empty());
    }
}
