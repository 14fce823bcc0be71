// Usage errors worded for the person who made them: CLI11 says "A subcommand is required" for
// `mcrt frobnicate`, which hides the word actually typed.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace mcrt {

// The one-line message (without "mcrt: error: ") for a CLI11 parse error of `app`.
std::string usage_error_message(const CLI::App& app, const CLI::ParseError& error, int argc,
                                char** argv);

}  // namespace mcrt
