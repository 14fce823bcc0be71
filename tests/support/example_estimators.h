// The user estimators of examples/estimators/, found on disk, as render settings take them.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "render/estimator_file.h"
#include "render/renderer.h"

namespace mcrt::test {

// Every examples/estimators/*.cl, sorted by name.
inline std::vector<std::string> example_estimator_files() {
    std::vector<std::string> files;
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(MCRT_EXAMPLES) + "/estimators"))
        if (entry.path().extension() == ".cl") files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
    return files;
}

// settings rendering with the user's estimator in `file`.
inline void use_estimator_file(RenderSettings& settings, const std::string& file) {
    settings.estimator_file = file;
    settings.estimator_source = read_estimator_file(file);
}

}  // namespace mcrt::test
