#include "cl/build_child.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "cl/binary_cache.h"
#include "cl/program.h"
#include "common/environment.h"
#include "common/signal_name.h"
#include "common/test_hooks.h"

extern char** environ;

namespace mcrt {

namespace fs = std::filesystem;

namespace {

const StopFlag* g_stop_flag = nullptr;

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

bool write_text(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    return bool(out);
}

const std::string kBuildDirectoryPrefix = "mcrt-build-";

// The PID in a build directory's name `mcrt-build-PID-XXXXXX`, or 0 when `name` is not one.
pid_t build_directory_owner(const std::string& name) {
    if (name.compare(0, kBuildDirectoryPrefix.size(), kBuildDirectoryPrefix) != 0) return 0;
    const std::string rest = name.substr(kBuildDirectoryPrefix.size());
    const size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || rest.size() - dash - 1 != 6) return 0;
    if (rest.find_first_not_of("0123456789") != dash) return 0;
    if (dash > 9) return 0;
    return pid_t(std::stol(rest.substr(0, dash)));
}

// Removes the build directories of processes that ended without removing their own (a render
// killed by SIGKILL while a child built its kernels): only directories of this user, named as
// BuildDirectory names them, whose PID names no process.
void sweep_stale_build_directories(const fs::path& parent) {
    std::error_code ec;
    for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
        const pid_t owner = build_directory_owner(it->path().filename().string());
        if (owner <= 0 || owner == ::getpid()) continue;
        struct stat st {};
        if (::lstat(it->path().c_str(), &st) != 0 || !S_ISDIR(st.st_mode) ||
            st.st_uid != ::getuid())
            continue;
        if (::kill(owner, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to ask
        std::error_code ignored;
        fs::remove_all(it->path(), ignored);
    }
}

// A private directory for one build's files (mkdtemp(3): mode 0700), removed with the object;
// its name holds this process's PID, so that a later build removes it if this process is killed.
struct BuildDirectory {
    fs::path path;
    BuildDirectory() {
        const fs::path parent = fs::temp_directory_path();
        sweep_stale_build_directories(parent);
        std::string pattern =
            (parent / (kBuildDirectoryPrefix + std::to_string(::getpid()) + "-XXXXXX")).string();
        if (::mkdtemp(pattern.data()) == nullptr)
            throw RuntimeError("cannot create a directory for a kernel build in " +
                               parent.string() + ": " + std::strerror(errno));
        path = pattern;
    }
    ~BuildDirectory() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};

// Writes a new file for the parent to read; never replaces or follows what is at the name.
bool write_new_file(const fs::path& path, const std::string& text) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0) return false;
    size_t written = 0;
    while (written < text.size()) {
        const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        written += size_t(n);
    }
    return ::close(fd) == 0 && written == text.size();
}

// The last non-empty line of a compiler's dump, which often names what failed.
std::string last_line(const std::string& text) {
    std::istringstream in(text);
    std::string line, last;
    while (std::getline(in, line))
        if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
    return last;
}

}  // namespace

void set_build_stop_flag(const StopFlag* flag) { g_stop_flag = flag; }

const std::string& build_child_executable() {
    static const std::string path = [] {
        if (const char* forced = environment(kEnvBuildChild); forced)
            return std::string(forced);  // a path, or "" for builds in this process
        std::error_code ec;
        fs::path self = fs::read_symlink("/proc/self/exe", ec);
        if (ec) return std::string();
        if (self.filename() == "mcrt") return self.string();
        // A test executable in build/tests/ finds build/mcrt.
        for (const fs::path& candidate :
             {self.parent_path() / "mcrt", self.parent_path().parent_path() / "mcrt"})
            if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0)
                return candidate.string();
        return std::string();
    }();
    return path;
}

std::vector<unsigned char> build_binary_in_child(const DeviceInfo& device,
                                                 const std::string& source,
                                                 const std::string& options) {
    BuildDirectory dir;
    if (!write_text(dir.path / "source.cl", source) || !write_text(dir.path / "options", options))
        throw RuntimeError("cannot write the kernel source into " + dir.path.string());
    const std::string exe = build_child_executable();
    const std::string index = std::to_string(device.index);
    const std::string dir_text = dir.path.string();
    const std::string log = (dir.path / "log").string();
    std::vector<char*> argv = {const_cast<char*>(exe.c_str()), const_cast<char*>("build-program"),
                               const_cast<char*>(dir_text.c_str()),
                               const_cast<char*>(index.c_str()), nullptr};

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0600);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    // Its own process group: a terminal's Ctrl-C reaches mcrt, which then ends the child itself.
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
    posix_spawnattr_setpgroup(&attributes, 0);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigaddset(&defaults, SIGPIPE);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, exe.c_str(), &actions, &attributes, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    if (spawned != 0)
        throw RuntimeError("cannot start " + exe + " to build kernels: " + std::strerror(spawned));

    int status = 0;
    for (;;) {
        pid_t done = ::waitpid(pid, &status, WNOHANG);
        if (done == pid) break;
        if (done < 0 && errno != EINTR)
            throw RuntimeError("waitpid: " + std::string(std::strerror(errno)));
        if (g_stop_flag && *g_stop_flag) {
            ::kill(pid, SIGKILL);
            while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            }
            throw RuntimeError("stopped while the kernels of device '" + device.name +
                               "' were building");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }

    const std::string variant = "options '" + options + "'";
    if (WIFSIGNALED(status)) {
        std::string dump = last_line(read_text(log));
        throw CompilerCrash("the compiler of device " + std::to_string(device.index) + " ('" +
                            device.name + "') died of " + signal_name(WTERMSIG(status)) +
                            " building the kernels with " + variant +
                            (dump.empty() ? "" : "; its last words: " + dump));
    }
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == 0) {
        std::string binary = read_text(dir.path / "binary");
        if (binary.empty())
            throw CompilerCrash("the kernel build for device '" + device.name +
                                "' returned no binary (" + variant + ")");
        return std::vector<unsigned char>(binary.begin(), binary.end());
    }
    std::string error = read_text(dir.path / "error");
    if (error.empty())
        throw CompilerCrash("the kernel build for device " + std::to_string(device.index) + " ('" +
                            device.name + "') exited with status " + std::to_string(code) +
                            " and no word (" + variant + "): " + last_line(read_text(log)));
    throw RuntimeError(error);
}

int run_build_program_child(const std::string& dir_text, int device_index) {
    // Ends with mcrt: an orphaned build is of use to no one.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    const fs::path dir = dir_text;
    // Run by hand, it must not replace a user's files: it works only in a build directory as
    // mcrt makes one (its name, this user's, mode 0700, the source and options in it, no result).
    {
        struct stat st {};
        std::string refusal;
        if (::lstat(dir.c_str(), &st) != 0)
            refusal = std::string(std::strerror(errno));
        else if (!S_ISDIR(st.st_mode) || build_directory_owner(dir.filename().string()) == 0 ||
                 st.st_uid != ::getuid() || (st.st_mode & 077) != 0 ||
                 !fs::is_regular_file(dir / "source.cl") || !fs::is_regular_file(dir / "options"))
            refusal = "not a kernel build directory of mcrt's (mcrt makes them itself)";
        else if (fs::symlink_status(dir / "binary").type() != fs::file_type::not_found ||
                 fs::symlink_status(dir / "error").type() != fs::file_type::not_found)
            refusal = "holds a result already; not replaced";
        if (!refusal.empty()) {
            std::fprintf(stderr, "mcrt: error: build-program: %s: %s\n", dir_text.c_str(),
                         refusal.c_str());
            return 2;
        }
    }
    try {
        std::vector<DeviceInfo> devices = enumerate_devices([](const std::string&) {});
        if (device_index < 0 || size_t(device_index) >= devices.size())
            throw std::runtime_error("build-program: no device " + std::to_string(device_index));
        DeviceContext device(devices[size_t(device_index)]);
        if (test_compiler_crash(device_index)) {
            std::signal(SIGSEGV, SIG_DFL);  // past a sanitizer's handler: die of the signal
            std::raise(SIGSEGV);
        }
        cl::Program program =
            build_program(device.context, device.info.device, read_text(dir / "source.cl"),
                          read_text(dir / "options"));
        std::vector<unsigned char> binary = program_binary(program, device.info.device);
        if (binary.empty()) throw std::runtime_error("the driver returned no binary");
        const fs::path partial = dir / "binary.partial";
        if (!write_new_file(partial, std::string(binary.begin(), binary.end())))
            throw std::runtime_error("cannot write " + partial.string());
        fs::rename(partial, dir / "binary");
        return 0;
    } catch (const RuntimeError& e) {  // the build failed: its log for the parent
        write_new_file(dir / "error", e.what());
        return 3;
    } catch (const std::exception& e) {
        write_new_file(dir / "error", e.what());
        return 1;
    }
}

}  // namespace mcrt
