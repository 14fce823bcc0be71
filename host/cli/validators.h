// CLI11 validators the commands share.
#pragma once

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace mcrt {

// CLI11's Range lets NaN through (both comparisons are false): reject non-finite values first.
// A number too large for a double is refused as such, and one so small that it rounds to 0 (a
// time limit of 1e-400 would read as none); denormals (4.9e-324) are finite and pass.
inline const CLI::Validator kFinite(
    [](std::string& text) {
        const char* begin = text.c_str();
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(begin, &end);
        const bool out_of_range = errno == ERANGE;
        if (end == begin || *end != '\0') return "'" + text + "' is not a number";
        if (!std::isfinite(v) && !out_of_range) return "'" + text + "' is not a finite number";
        if (out_of_range && std::fabs(v) > 1)
            return "'" + text + "' is beyond the largest finite number (1.8e308)";
        if (out_of_range && v == 0)
            return "'" + text + "' is too small to tell from 0 (the smallest is 4.9e-324)";
        return std::string();
    },
    "FINITE");

// An empty value (`--out ""`, an unset shell variable) is a bad value, never "not given": it would
// otherwise select a default or skip an output silently.
inline const CLI::Validator kNotEmpty(
    [](std::string& text) {
        return text.empty() ? std::string("an empty value is not allowed") : std::string();
    },
    "");  // no word in --help: every option has it

// Adds kNotEmpty to every option that takes a value, of `app` and all its subcommands.
inline void refuse_empty_values(CLI::App& app) {
    for (CLI::Option* option : app.get_options())
        if (option->get_type_size_max() > 0) option->check(kNotEmpty);
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
        refuse_empty_values(*sub);
}

}  // namespace mcrt
