// Write to a temporary name, then rename: readers see the old file or the whole new one.
#include "common/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "common/error.h"

namespace mcrt {

namespace fs = std::filesystem;

namespace {

// Hidden sibling of `target`; pid and counter keep concurrent writers (processes, threads) apart.
fs::path temporary_sibling(const fs::path& target) {
    static std::atomic<unsigned> counter{0};
    std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                       "-" + std::to_string(counter++);
    return target.parent_path() / name;
}

}  // namespace

void write_atomically(const std::string& path,
                      const std::function<void(const std::string&)>& write) {
    fs::path target(path);
    // rename(2) is atomic only within one file system, so the temporary lives beside the target.
    fs::path directory = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    if (!fs::is_directory(directory, ec)) {
        throw InputError(path + ": directory does not exist");
    }

    fs::path temporary = temporary_sibling(target);
    try {
        write(temporary.string());
    } catch (...) {
        fs::remove(temporary, ec);
        throw;
    }
    if (std::rename(temporary.c_str(), target.c_str()) != 0) {
        int error = errno;
        fs::remove(temporary, ec);
        throw RuntimeError(path +
                           ": cannot rename temporary file into place: " + std::strerror(error));
    }
}

}  // namespace mcrt
