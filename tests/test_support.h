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

// Path of a file under ../shared/scenes, or a skip when that directory is absent.
inline std::string shared_scene(const std::string& relative) {
    std::string path = std::string(MCRT_SHARED_SCENES) + "/" + relative;
    if (!std::filesystem::exists(path)) skip_test("shared scene not present: " + path);
    return path;
}

}  // namespace mcrt::test
