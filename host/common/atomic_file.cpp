// Write to a temporary file, then rename: readers see the old file or the whole new one, and no
// temporary outlives its process (ROBUSTNESS.md "Outputs").
#include "common/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "common/error.h"
#include "common/regular_file.h"
#include "common/test_hooks.h"

namespace mcrt {

namespace fs = std::filesystem;

namespace {

const std::string kTmpTag = ".tmp-";

// Hidden sibling of `target`; pid and counter keep concurrent writers (processes, threads) apart.
fs::path temporary_sibling(const fs::path& target) {
    static std::atomic<unsigned> counter{0};
    std::string name = "." + target.filename().string() + kTmpTag + std::to_string(::getpid()) +
                       "-" + std::to_string(counter++);
    return target.parent_path() / name;
}

// The PID in `.NAME.tmp-PID-N`, or 0 when `file` is not a temporary of NAME.
pid_t temporary_owner(const std::string& file, const std::string& name) {
    const std::string prefix = "." + name + kTmpTag;
    if (file.compare(0, prefix.size(), prefix) != 0) return 0;
    const std::string rest = file.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size()) return 0;
    if (rest.find_first_not_of("0123456789-") != std::string::npos) return 0;
    if (rest.find('-', dash + 1) != std::string::npos) return 0;
    try {
        const long pid = std::stol(rest.substr(0, dash));
        return pid > 0 && pid <= 0x3fffffff ? static_cast<pid_t>(pid) : 0;
    } catch (const std::exception&) {
        return 0;
    }
}

[[noreturn]] void fail_rename(const std::string& path, int error) {
    throw RuntimeError(path + ": cannot rename temporary file into place: " + std::strerror(error));
}

// The O_TMPFILE path: true when the file was written and renamed into place, false when the file
// system does not support unnamed temporaries (nothing was done then).
bool write_unnamed(const fs::path& target, const fs::path& directory,
                   const std::function<void(const std::string&)>& write) {
#ifdef O_TMPFILE
    if (test_no_tmpfile()) return false;
    const int fd = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (fd < 0) {
        // EISDIR / EOPNOTSUPP / EINVAL: no O_TMPFILE here; other errors show again on the
        // named path, with its own message.
        return false;
    }
    const std::string proc_path = "/proc/self/fd/" + std::to_string(fd);
    if (::access(proc_path.c_str(), W_OK) != 0) {  // no /proc: cannot reopen or link it
        ::close(fd);
        return false;
    }
    try {
        write(proc_path);
        test_pause("write");
    } catch (...) {
        ::close(fd);  // the unnamed inode dies with its last descriptor
        throw;
    }
    // linkat cannot replace, so the file gets its hidden name only for the rename's instant.
    const fs::path temporary = temporary_sibling(target);
    if (::linkat(AT_FDCWD, proc_path.c_str(), AT_FDCWD, temporary.c_str(), AT_SYMLINK_FOLLOW) != 0) {
        const int error = errno;
        ::close(fd);
        throw RuntimeError(target.string() + ": cannot link the written file into " +
                           directory.string() + ": " + std::strerror(error));
    }
    ::close(fd);
    if (std::rename(temporary.c_str(), target.c_str()) != 0) {
        const int error = errno;
        std::error_code ec;
        fs::remove(temporary, ec);
        fail_rename(target.string(), error);
    }
    return true;
#else
    (void)target, (void)directory, (void)write;
    return false;
#endif
}

// A process that has ended but is not yet reaped (state Z in /proc/PID/stat, proc(5)): a render
// killed with its supervisor is an orphan until init reaps it, which can take seconds.
bool is_zombie(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
    std::string stat;
    std::getline(in, stat);
    const size_t paren = stat.rfind(')');  // the command name may hold spaces and parentheses
    return paren != std::string::npos && paren + 2 < stat.size() && stat[paren + 2] == 'Z';
}

}  // namespace

int sweep_stale_temporaries(const std::string& path) {
    const fs::path target(path);
    const fs::path directory = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const std::string name = target.filename().string();
    int removed = 0;
    std::error_code ec;
    for (fs::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
        const pid_t owner = temporary_owner(it->path().filename().string(), name);
        if (owner == 0 || owner == ::getpid()) continue;
        // Alive (or not ours to signal, EPERM): keep. Only a PID that names no process, or a zombie,
        // is stale.
        if ((::kill(owner, 0) == 0 || errno != ESRCH) && !is_zombie(owner)) continue;
        std::error_code remove_ec;
        if (fs::remove(it->path(), remove_ec)) ++removed;
    }
    return removed;
}

void write_atomically(const std::string& path,
                      const std::function<void(const std::string&)>& write) {
    fs::path target(path);
    // rename(2) is atomic only within one file system, so the temporary lives beside the target.
    fs::path directory = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    if (!fs::is_directory(directory, ec)) {
        throw InputError(path + ": directory does not exist");
    }
    // rename(2) replaces whatever has the name: a device, a FIFO, an empty directory.
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        throw InputError(path + ": is " + file_kind_name(st.st_mode) + "; refusing to replace it");
    }
    sweep_stale_temporaries(path);
    test_pause("before-write");

    if (write_unnamed(target, directory, write)) return;

    fs::path temporary = temporary_sibling(target);
    try {
        write(temporary.string());
        test_pause("write");
    } catch (...) {
        fs::remove(temporary, ec);
        throw;
    }
    if (std::rename(temporary.c_str(), target.c_str()) != 0) {
        int error = errno;
        fs::remove(temporary, ec);
        fail_rename(path, error);
    }
}

}  // namespace mcrt
