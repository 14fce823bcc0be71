// Write to temporary files, then rename: readers see the old files or the whole new set, and no
// temporary outlives its process (ROBUSTNESS.md "Outputs").
#include "common/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <system_error>

#include "common/error.h"
#include "common/output_paths.h"
#include "common/stop_signals.h"
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

fs::path directory_of(const fs::path& target) {
    return target.parent_path().empty() ? fs::path(".") : target.parent_path();
}

// An unnamed inode in `directory` (O_TMPFILE, open(2)), -1 where the file system or the
// platform has none, or /proc is missing to reopen it by.
int open_unnamed(const fs::path& directory) {
#ifdef O_TMPFILE
    if (test_no_tmpfile()) return -1;
    const int fd = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (fd < 0) return -1;  // EISDIR / EOPNOTSUPP / EINVAL, or an error the named path names
    const std::string proc_path = "/proc/self/fd/" + std::to_string(fd);
    if (::access(proc_path.c_str(), W_OK) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
#else
    (void)directory;
    return -1;
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

// Holds an exclusive flock(2) on each distinct directory given. A directory is distinct by its
// device and inode, not its name: flock(2) locks belong to an open file description, so one
// directory named two ways (`o.exr` beside `$PWD/s.json`, `out/./a.png`, `/proc/self/fd/1`'s
// file) and opened twice would wait on itself forever. The locks are taken in (device, inode)
// order, so two sets over the same directories cannot deadlock; released by close(2). A stop
// signal while another process holds a lock ends the wait with an error (nothing is written).
class DirectoryLocks {
  public:
    explicit DirectoryLocks(const std::vector<std::string>& directories) {
        struct Opened {
            dev_t device;
            ino_t inode;
            int fd;
            std::string name;
        };
        std::vector<Opened> opened;
        for (const std::string& dir : directories) {
            const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
            if (fd < 0) continue;  // unlockable: the renames are still each atomic
            struct stat st {};
            if (::fstat(fd, &st) != 0) {
                ::close(fd);
                continue;
            }
            opened.push_back({st.st_dev, st.st_ino, fd, dir});
        }
        std::sort(opened.begin(), opened.end(), [](const Opened& a, const Opened& b) {
            return a.device != b.device ? a.device < b.device : a.inode < b.inode;
        });
        std::vector<const Opened*> distinct;
        for (size_t i = 0; i < opened.size(); ++i) {
            if (i > 0 && opened[i].device == opened[i - 1].device &&
                opened[i].inode == opened[i - 1].inode) {
                ::close(opened[i].fd);  // the same directory under another name
                continue;
            }
            fds_.push_back(opened[i].fd);
            distinct.push_back(&opened[i]);
        }
        for (const Opened* directory : distinct) lock(directory->fd, directory->name);
    }
    ~DirectoryLocks() {
        for (int fd : fds_) ::close(fd);
    }
    DirectoryLocks(const DirectoryLocks&) = delete;
    DirectoryLocks& operator=(const DirectoryLocks&) = delete;

  private:
    void lock(int fd, const std::string& name) {
        if (::flock(fd, LOCK_EX | LOCK_NB) == 0 || errno != EWOULDBLOCK) return;
        test_pause("commit-wait");  // another set holds it: the tests see this one wait
        // Polled rather than blocking, so that a stop signal at any instant ends the wait.
        while (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            if (errno != EWOULDBLOCK && errno != EINTR) return;  // unlockable: renames stay atomic
            if (stop_requested()) {
                for (int open_fd : fds_) ::close(open_fd);
                fds_.clear();
                throw RuntimeError("stopped while another process was writing its outputs in " +
                                   name + "; no output written");
            }
            ::usleep(10000);
        }
    }

    std::vector<int> fds_;
};

}  // namespace

struct OutputSet::Output {
    std::string option, path;  // as given
    fs::path target;           // after its links: what the commit replaces
    int fd = -1;               // the unnamed temporary, or -1
    std::string temporary;     // what the writer opens: /proc/self/fd/N or the named sibling
    fs::path linked;           // the name the temporary has during the commit

    std::string name() const { return option.empty() ? path : option + " " + path; }

    void remove_files() noexcept {
        std::error_code ec;
        if (fd >= 0) {
            ::close(fd);  // the unnamed inode dies with its last descriptor
            fd = -1;
        } else if (!temporary.empty()) {
            fs::remove(temporary, ec);
        }
        if (!linked.empty()) fs::remove(linked, ec);
        temporary.clear();
        linked.clear();
    }
};

OutputSet::OutputSet() = default;

OutputSet::~OutputSet() { discard(); }

void OutputSet::add(const std::string& option, const std::string& path) {
    if (path.empty()) return;
    auto output = std::make_unique<Output>();
    output->option = option;
    output->path = path;
    outputs_.push_back(std::move(output));
}

void OutputSet::check_inputs(const std::vector<std::string>& inputs) const {
    std::vector<OutputFile> files;
    for (const auto& output : outputs_) files.push_back({output->option, output->path, {}});
    check_outputs(files, inputs);
}

void OutputSet::prepare(const std::vector<std::string>& inputs) {
    std::vector<OutputFile> files;
    for (const auto& output : outputs_) files.push_back({output->option, output->path, {}});
    check_outputs(files, inputs);
    for (size_t i = 0; i < outputs_.size(); ++i) {
        Output& output = *outputs_[i];
        output.target = files[i].target;
        const fs::path directory = directory_of(output.target);
        sweep_stale_temporaries(output.target.string());
        output.fd = open_unnamed(directory);
        if (output.fd >= 0) {
            output.temporary = "/proc/self/fd/" + std::to_string(output.fd);
            continue;
        }
        // The named temporary, created now: a directory that takes no new file is refused
        // before any work, not after it.
        const fs::path named = temporary_sibling(output.target);
        const int fd = ::open(named.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
            const int error = errno;
            discard();
            throw InputError(output.name() + ": cannot create a file in " + directory.string() +
                             ": " + std::strerror(error));
        }
        ::close(fd);
        output.temporary = named.string();
    }
    prepared_ = true;
}

const std::string& OutputSet::temporary(const std::string& path) const {
    for (const auto& output : outputs_)
        if (output->path == path && !output->temporary.empty()) return output->temporary;
    throw RuntimeError(path + ": not an output of this command, or already written");
}

void OutputSet::commit() {
    if (!prepared_) throw RuntimeError("output set committed before it was prepared");
    std::vector<std::string> directories;
    for (const auto& output : outputs_)
        directories.push_back(directory_of(output->target).string());
    test_pause("write");
    try {
        DirectoryLocks locks(directories);
        // Every temporary gets its name first (linkat cannot replace, so an unnamed one is
        // linked as a hidden sibling), then the renames: a failure before them changes nothing.
        for (const auto& output : outputs_) {
            struct stat st {};
            if (::stat(output->target.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
                throw RuntimeError(output->name() +
                                   ": became something else than a regular file; not replaced");
            }
            if (output->fd < 0) {
                output->linked = output->temporary;
                continue;
            }
            const fs::path hidden = temporary_sibling(output->target);
            if (::linkat(AT_FDCWD, output->temporary.c_str(), AT_FDCWD, hidden.c_str(),
                         AT_SYMLINK_FOLLOW) != 0) {
                throw RuntimeError(output->name() + ": cannot link the written file into " +
                                   directory_of(output->target).string() + ": " +
                                   std::strerror(errno));
            }
            output->linked = hidden;
        }
        bool first = true;
        for (const auto& output : outputs_) {
            if (std::rename(output->linked.c_str(), output->target.c_str()) != 0) {
                throw RuntimeError(
                    output->target.string() +
                    ": cannot rename temporary file into place: " + std::strerror(errno));
            }
            output->linked.clear();
            if (output->fd < 0) output->temporary.clear();  // it is the target now
            if (first) test_pause("commit");
            first = false;
        }
    } catch (...) {
        discard();
        throw;
    }
    discard();  // closes the unnamed descriptors
    prepared_ = false;
}

void OutputSet::discard() noexcept {
    for (const auto& output : outputs_) output->remove_files();
    prepared_ = false;
}

int sweep_stale_temporaries(const std::string& path) {
    const fs::path target(path);
    const fs::path directory = directory_of(target);
    const std::string name = target.filename().string();
    int removed = 0;
    std::error_code ec;
    for (fs::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
        const pid_t owner = temporary_owner(it->path().filename().string(), name);
        if (owner == 0 || owner == ::getpid()) continue;
        // Alive (or not ours to signal, EPERM): keep. Only a PID that names no process, or a
        // zombie, is stale.
        if ((::kill(owner, 0) == 0 || errno != ESRCH) && !is_zombie(owner)) continue;
        std::error_code remove_ec;
        if (fs::remove(it->path(), remove_ec)) ++removed;
    }
    return removed;
}

void write_atomically(const std::string& path,
                      const std::function<void(const std::string&)>& write) {
    OutputSet set;
    set.add("", path);
    set.prepare({});
    test_pause("before-write");
    write(set.temporary(path));
    set.commit();
}

}  // namespace mcrt
