#include "cl/no_device.h"

#include <dlfcn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>
#include <vector>

#include "common/environment.h"
#include "common/error.h"
#include "common/regular_file.h"

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

std::string joined(const std::vector<std::string>& items) {
    std::string text;
    for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
    return text;
}

// The device types of the installed PoCL: its modules libpocl-devices-NAME.so, where
// distributions put them; else the types PoCL 3 documents ("POCL_DEVICES", PoCL's manual).
std::vector<std::string> pocl_device_types() {
    std::set<std::string> types;
    for (const char* dir :
         {"/usr/lib/x86_64-linux-gnu/pocl", "/usr/lib/aarch64-linux-gnu/pocl", "/usr/lib64/pocl",
          "/usr/lib/pocl", "/usr/local/lib/pocl", "/usr/local/lib64/pocl"}) {
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(dir, ec)) {
            const std::string name = entry.path().filename().string();
            const std::string prefix = "libpocl-devices-", suffix = ".so";
            if (name.size() > prefix.size() + suffix.size() && name.rfind(prefix, 0) == 0 &&
                name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
                types.insert(
                    name.substr(prefix.size(), name.size() - prefix.size() - suffix.size()));
        }
    }
    types.insert("basic");  // built into libpocl where it has no module
    if (types.size() == 1)
        types.insert(
            {"pthread", "tbb", "cuda", "hsa", "level0", "vulkan", "almaif", "remote", "proxy"});
    return {types.begin(), types.end()};
}

// When POCL_DEVICES (space-separated device types) names none PoCL has, why; else "".
std::string pocl_devices_problem() {
    const char* value = environment(kEnvPoclDevices);
    if (!value) return {};
    const std::vector<std::string> known = pocl_device_types();
    std::istringstream words(value);
    std::string word;
    std::vector<std::string> unknown;
    bool any_known = false;
    while (words >> word) {
        if (std::find(known.begin(), known.end(), word) != known.end())
            any_known = true;
        else
            unknown.push_back(word);
    }
    if (any_known) return {};
    return std::string("POCL_DEVICES='") + value + "' names " +
           (unknown.empty() ? std::string("no device type")
                            : "no device type PoCL has (" + joined(unknown) + ")") +
           "; it accepts a space-separated list of " + joined(known);
}

// The ICD loader's vendor files: OCL_ICD_VENDORS (a directory, or one .icd file), else
// /etc/OpenCL/vendors (ocl-icd's documentation).
std::vector<fs::path> icd_files() {
    fs::path where = "/etc/OpenCL/vendors";
    if (const char* vendors = environment(kEnvOclIcdVendors); vendors && *vendors) where = vendors;
    std::error_code ec;
    if (!fs::is_directory(where, ec)) return {where};
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(where, ec))
        if (entry.path().extension() == ".icd") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

// An ICD file the loader cannot read safely, as words ("starts with a NUL byte, ..."), or "".
std::string icd_file_problem(const fs::path& file) {
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0 || S_ISDIR(st.st_mode)) return {};  // skipped by the loader
    if (!S_ISREG(st.st_mode))
        return "is " + file_kind_name(st.st_mode) + ", which the ICD loader would wait on forever";
    std::vector<unsigned char> first;
    std::string why;
    FileSizeLimits limits;
    limits.read_bytes = 1;
    if (!read_regular_file(file.string(), first, why, limits)) return {};  // the loader skips it
    if (!first.empty() && first[0] == 0)
        return "starts with a NUL byte (it names no library), which the ICD loader crashes on";
    return {};
}

// The address-space limit (ulimit -v) as words, or "" when there is none.
std::string address_space_limit() {
    struct rlimit limit {};
    if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return {};
    return "; the address-space limit (ulimit -v) is " + std::to_string(limit.rlim_cur >> 20) +
           " MiB";
}

// An installed OpenCL implementation that cannot be loaded (a memory limit: "failed to map
// segment from shared object"), which the ICD loader skips without a word; else "".
std::string icd_load_problem() {
    for (const fs::path& file : icd_files()) {
        std::ifstream in(file);
        std::string library;
        if (!std::getline(in, library) || library.empty()) continue;
        void* handle = ::dlopen(library.c_str(), RTLD_LAZY | RTLD_LOCAL);
        if (handle) continue;  // loads: left loaded, as the process is about to end
        const char* why = ::dlerror();
        return "the OpenCL implementation " + library + " (" + file.string() +
               ") cannot be loaded: " + (why ? why : "unknown reason") + address_space_limit();
    }
    return {};
}

}  // namespace

std::string pocl_cache_problem() {
    const std::string cache = pocl_cache_directory();
    if (cache.empty()) return {};
    const std::string why = why_unusable(cache);
    if (why.empty()) return {};
    return "PoCL's kernel cache directory " + cache + " cannot be created (" + why +
           "); set POCL_CACHE_DIR to a writable directory";
}

void check_icd_files() {
    for (const fs::path& file : icd_files()) {
        const std::string problem = icd_file_problem(file);
        if (problem.empty()) continue;
        const char* vendors = environment(kEnvOclIcdVendors);
        throw RuntimeError(
            "the OpenCL ICD file " + file.string() + " " + problem + "; remove it" +
            (vendors && *vendors ? ", or set OCL_ICD_VENDORS to a directory without it" : ""));
    }
}

std::string no_device_message() {
    for (const std::string& problem :
         {pocl_devices_problem(), pocl_cache_problem(), icd_load_problem()})
        if (!problem.empty()) return "no OpenCL device found: " + problem;
    return "no OpenCL device found (is an ICD such as PoCL installed?)" + address_space_limit();
}

}  // namespace mcrt
