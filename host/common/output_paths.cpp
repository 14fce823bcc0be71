#include "common/output_paths.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "common/error.h"
#include "common/regular_file.h"

namespace mcrt {

namespace fs = std::filesystem;

namespace {

// Links followed before a chain counts as a loop: Linux's limit for one path lookup
// (path_resolution(7), "at most 40 symbolic links").
constexpr int kMaxLinks = 40;

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

// "--out a.exr", or the path alone for a file that no option names.
std::string named(const std::string& option, const std::string& path) {
    return option.empty() ? path : option + " " + path;
}

std::string named(const OutputFile& output) { return named(output.option, output.path); }

}  // namespace

std::string resolve_output(const std::string& option, const std::string& path) {
    const std::string name = named(option, path);
    // What the whole chain ends at (stat follows every link, /proc/self/fd/N's magic ones too):
    // a pipe or terminal behind /dev/stdout is refused here, before its links are read.
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        throw InputError(name + ": is " + file_kind_name(st.st_mode) + "; refusing to replace it");
    }
    fs::path current(path);
    for (int links = 0;; ++links) {
        struct stat lst {};
        if (::lstat(current.c_str(), &lst) != 0 || !S_ISLNK(lst.st_mode)) break;
        if (links == kMaxLinks) throw InputError(name + ": too many levels of symbolic links");
        std::error_code ec;
        const fs::path next = fs::read_symlink(current, ec);
        if (ec)
            throw InputError(name + ": cannot read the link " + current.string() + ": " +
                             ec.message());
        current = next.is_absolute() ? next : current.parent_path() / next;
    }
    const fs::path dir = current.parent_path();
    struct stat dst {};
    if (!dir.empty() && ::stat(dir.c_str(), &dst) != 0) {
        throw InputError(name + ": directory " + dir.string() + " does not exist");
    }
    if (!dir.empty() && !S_ISDIR(dst.st_mode)) {
        throw InputError(name + ": " + dir.string() + " is not a directory");
    }
    if (::stat(current.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        throw InputError(name + ": is " + file_kind_name(st.st_mode) + "; refusing to replace it");
    }
    return current.string();
}

void check_outputs(std::vector<OutputFile>& outputs, const std::vector<std::string>& inputs) {
    std::vector<std::pair<const OutputFile*, FileIdentity>> seen;
    for (OutputFile& output : outputs) {
        if (output.path.empty()) continue;
        output.target = resolve_output(output.option, output.path);
        const FileIdentity id = identify(output.target);
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
