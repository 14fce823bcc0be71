// CLI11 validators the commands share.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace mcrt {

// CLI11's Range lets NaN through (both comparisons are false): reject non-finite values first.
inline const CLI::Validator kFinite(
    [](std::string& text) {
        try {
            size_t used = 0;
            double v = std::stod(text, &used);
            if (used == text.size() && std::isfinite(v)) return std::string();
        } catch (const std::exception&) {
        }
        return "'" + text + "' is not a finite number";
    },
    "FINITE");

}  // namespace mcrt
