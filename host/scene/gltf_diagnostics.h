// What every part of the glTF import reports and checks with: errors that name the file and the
// glTF element, warnings once per kind, an index checked before it is followed, finite values.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <set>
#include <string>
#include <vector>

#include "common/error.h"
#include "scene/gltf_import.h"

namespace mcrt::gltf {

class Diagnostics {
  public:
    Diagnostics(std::string path, const WarningSink& sink) : path_(std::move(path)), sink_(sink) {}

    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw InputError(path_ + ": " + element + ": " + what);
    }
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }

    void warn_once(const std::string& kind, const std::string& message) {
        if (!warned_.insert(kind).second) return;
        if (sink_) sink_(path_ + ": " + message);
    }

  private:
    std::string path_;
    const WarningSink& sink_;
    std::set<std::string> warned_;
};

// A number as a person would write it (std::to_string prints 0.000000 for 1e-9).
std::string format_number(double value);

// "node 3", "accessor 0": how messages name the element `index` of a top-level array.
std::string element_name(const char* kind, size_t index);

bool all_finite(const std::vector<double>& values);

inline bool is_finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline double max_component(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// tinygltf does not check that an index is in range: every index is checked where it is followed.
// The element `index` of `items`, or an error "<referrer>: <what> <index> out of range".
template <typename T>
const T& checked_at(const std::vector<T>& items, long long index, const std::string& what,
                    const std::string& referrer, const Diagnostics& diag) {
    if (index < 0 || static_cast<unsigned long long>(index) >= items.size()) {
        diag.fail(referrer, what + " " + std::to_string(index) + " out of range");
    }
    return items[static_cast<size_t>(index)];
}

}  // namespace mcrt::gltf
