// CLI11 validators the commands share.
#pragma once

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

namespace mcrt {

// CLI11's Range lets NaN through (both comparisons are false): reject non-finite values first,
// for an option read as T (double or float). Each refusal says its true reason: a number beyond
// T's range is too large, one that rounds to 0 in T too small (a --time-limit of 1e-400 or an
// --ao-distance of 1e-50 would read as 0: no limit, unbounded); denormals (4.9e-324 as a double,
// 1e-40 as a float) are finite and pass.
template <typename T>
CLI::Validator finite_number() {
    return CLI::Validator(
        [](std::string& text) {
            auto figure = [](T v) {
                std::ostringstream out;
                out << std::setprecision(2) << double(v);
                return out.str();
            };
            const char* begin = text.c_str();
            char* end = nullptr;
            errno = 0;
            const long double v = std::strtold(begin, &end);  // CLI11 reads values with strtold
            const bool out_of_range = errno == ERANGE;
            if (end == begin || *end != '\0') return "'" + text + "' is not a number";
            if (std::isnan(v) || (std::isinf(v) && !out_of_range))
                return "'" + text + "' is not a finite number";
            if (std::isinf(v) || std::fabs(v) > std::numeric_limits<T>::max())
                return "'" + text + "' is beyond the largest finite number (" +
                       figure(std::numeric_limits<T>::max()) + ")";
            if (v != 0 && T(v) == 0)
                return "'" + text + "' is too small to tell from 0 (the smallest is " +
                       figure(std::numeric_limits<T>::denorm_min()) + ")";
            return std::string();
        },
        "FINITE");
}

inline const CLI::Validator kFinite = finite_number<double>();      // options read as double
inline const CLI::Validator kFiniteFloat = finite_number<float>();  // options read as float

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
