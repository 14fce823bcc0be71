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
