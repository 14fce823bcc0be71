// Formatting shared by the glTF import's messages.
#include "scene/gltf_diagnostics.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mcrt::gltf {

std::string format_number(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

std::string element_name(const char* kind, size_t index) {
    return std::string(kind) + " " + std::to_string(index);
}

bool all_finite(const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace mcrt::gltf
