#include "common/output_paths.h"

#include <sys/stat.h>

#include <filesystem>

#include "common/error.h"
#include "common/regular_file.h"

namespace mcrt {

namespace fs = std::filesystem;

namespace {

// A file's identity: device and inode when it exists, else its normalized absolute path.
struct FileIdentity {
    bool exists = false;
    dev_t device = 0;
    ino_t inode = 0;
    std::string normalized;

    bool same_as(const FileIdentity& other) const {
        if (exists && other.exists) return device == other.device && inode == other.inode;
        return normalized == other.normalized;
    }
};

FileIdentity identify(const std::string& path) {
    FileIdentity id;
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        id.exists = true;
        id.device = st.st_dev;
        id.inode = st.st_ino;
    }
    std::error_code ec;
    fs::path absolute = fs::absolute(path, ec);
    fs::path normal = ec ? fs::path(path) : fs::weakly_canonical(absolute, ec);
    id.normalized = (ec ? absolute.lexically_normal() : normal).string();
    return id;
}

std::string named(const OutputFile& output) { return output.option + " " + output.path; }

}  // namespace

void check_outputs(const std::vector<OutputFile>& outputs, const std::vector<std::string>& inputs) {
    std::vector<std::pair<const OutputFile*, FileIdentity>> seen;
    for (const OutputFile& output : outputs) {
        if (output.path.empty()) continue;
        const fs::path dir = fs::path(output.path).parent_path();
        if (!dir.empty() && !fs::is_directory(dir)) {
            throw InputError(named(output) + ": directory " + dir.string() + " does not exist");
        }
        struct stat st {};
        if (::stat(output.path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
            throw InputError(named(output) + ": is " + file_kind_name(st.st_mode) +
                             "; refusing to replace it");
        }
        const FileIdentity id = identify(output.path);
        for (const auto& [other, other_id] : seen) {
            if (id.same_as(other_id)) {
                throw InputError(named(output) + ": the same file as " + named(*other));
            }
        }
        for (const std::string& input : inputs) {
            if (id.exists && id.same_as(identify(input))) {
                throw InputError(named(output) + ": is the input " + input +
                                 "; refusing to overwrite it");
            }
        }
        seen.emplace_back(&output, id);
    }
}

}  // namespace mcrt
