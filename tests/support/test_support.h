// Helpers shared by the tests.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

namespace mcrt::test {

// ctest reports a test that exits with status 4 as skipped (SKIP_RETURN_CODE in
// tests/CMakeLists.txt); Catch2 v2 has no skip of its own. Each ctest test runs one test case.
[[noreturn]] inline void skip_test(const std::string& why) {
    std::cout << "SKIPPED: " << why << std::endl;
    std::exit(4);
}

// Path of a scene shipped in the repository's scenes/ (scenes/SOURCES.md).
inline std::string scene_path(const std::string& relative) {
    return std::string(MCRT_SCENES) + "/" + relative;
}

// Path of a file under the directory of large scenes (the CMake cache variable
// MCRT_EXTENDED_SCENES, ../shared/scenes by default), which only the tests tagged [extended]
// use: ctest runs them (label `extended`, scripts/test --extended) only where that directory
// existed when CMake configured the build. A skip if it has gone since.
inline std::string extended_scene(const std::string& relative) {
    std::string path = std::string(MCRT_EXTENDED_SCENES) + "/" + relative;
    if (!std::filesystem::exists(path)) skip_test("extended scene not present: " + path);
    return path;
}

}  // namespace mcrt::test
