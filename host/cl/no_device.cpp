#include "cl/no_device.h"

#include "common/environment.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace mcrt {

namespace fs = std::filesystem;

namespace {

// PoCL's cache directory: POCL_CACHE_DIR, else $XDG_CACHE_HOME/pocl, else $HOME/.cache/pocl.
std::string pocl_cache_directory() {
    if (const char* dir = environment(kEnvPoclCacheDir); dir && *dir) return dir;
    if (const char* xdg = environment(kEnvXdgCacheHome); xdg && *xdg)
        return std::string(xdg) + "/pocl";
    if (const char* home = environment(kEnvHome); home && *home)
        return std::string(home) + "/.cache/pocl";
    return {};
}

// Why `dir` cannot be a writable directory, or "" when it is (or could be created).
std::string why_unusable(const fs::path& dir) {
    std::error_code ec;
    if (fs::is_directory(dir, ec)) {
        return ::access(dir.c_str(), W_OK | X_OK) == 0 ? std::string() : "not writable";
    }
    // Walk up to the first existing ancestor: it must be a writable directory.
    fs::path existing = dir;
    while (!existing.empty() && !fs::exists(existing, ec)) {
        if (existing == existing.parent_path()) break;
        existing = existing.parent_path();
    }
    if (existing.empty()) existing = ".";
    if (!fs::is_directory(existing, ec)) return existing.string() + " is not a directory";
    if (::access(existing.c_str(), W_OK | X_OK) != 0) return existing.string() + " is not writable";
    return {};
}

}  // namespace

std::string no_device_message() {
    const std::string plain = "no OpenCL device found (is an ICD such as PoCL installed?)";
    const std::string cache = pocl_cache_directory();
    if (cache.empty()) return plain;
    const std::string why = why_unusable(cache);
    if (why.empty()) return plain;
    return "no OpenCL device found: PoCL's kernel cache directory " + cache +
           " cannot be created (" + why + "); set POCL_CACHE_DIR to a writable directory";
}

}  // namespace mcrt
