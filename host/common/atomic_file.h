// Outputs appear complete or not at all (DESIGN.md "Nothing is written to --out unless ...").
#pragma once

#include <functional>
#include <string>

namespace mcrt {

// Calls write(temporary_path) for a temporary name in the directory of `path`, then renames it
// to `path`. If write throws, the temporary file is removed and the exception propagates.
void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write);

}  // namespace mcrt
