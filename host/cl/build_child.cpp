#include "cl/build_child.h"

#include "common/environment.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "cl/binary_cache.h"
#include "cl/program.h"
#include "common/signal_name.h"
#include "common/test_hooks.h"

extern char** environ;

namespace mcrt {

namespace fs = std::filesystem;

namespace {

const volatile std::sig_atomic_t* g_stop_flag = nullptr;

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

// A private directory for one build's files, removed with the object.
struct BuildDirectory {
    fs::path path;
    BuildDirectory() {
        std::string pattern = (fs::temp_directory_path() / "mcrt-build-XXXXXX").string();
        if (::mkdtemp(pattern.data()) == nullptr)
            throw RuntimeError("cannot create a directory for a kernel build in " +
                               fs::temp_directory_path().string() + ": " + std::strerror(errno));
        path = pattern;
    }
    ~BuildDirectory() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};

// The last non-empty line of a compiler's dump, which often names what failed.
std::string last_line(const std::string& text) {
    std::istringstream in(text);
    std::string line, last;
    while (std::getline(in, line))
        if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
    return last;
}

}  // namespace

void set_build_stop_flag(const volatile std::sig_atomic_t* flag) { g_stop_flag = flag; }

const std::string& build_child_executable() {
    static const std::string path = [] {
        if (const char* forced = environment(kEnvBuildChild); forced)
            return std::string(forced);  // a path, or "" for builds in this process
        std::error_code ec;
        fs::path self = fs::read_symlink("/proc/self/exe", ec);
        if (ec) return std::string();
        if (self.filename() == "mcrt") return self.string();
        // A test executable in build/tests/ finds build/mcrt.
        for (const fs::path& candidate : {self.parent_path() / "mcrt",
                                          self.parent_path().parent_path() / "mcrt"})
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
    std::vector<char*> argv = {const_cast<char*>(exe.c_str()),
                               const_cast<char*>("build-program"),
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
        if (done < 0 && errno != EINTR) throw RuntimeError("waitpid: " + std::string(std::strerror(errno)));
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
        throw CompilerCrash("the kernel build for device " + std::to_string(device.index) +
                            " ('" + device.name + "') exited with status " +
                            std::to_string(code) + " and no word (" + variant + "): " +
                            last_line(read_text(log)));
    throw RuntimeError(error);
}

int run_build_program_child(const std::string& dir_text, int device_index) {
    // Ends with mcrt: an orphaned build is of use to no one.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    const fs::path dir = dir_text;
    try {
        std::vector<DeviceInfo> devices = enumerate_devices([](const std::string&) {});
        if (device_index < 0 || size_t(device_index) >= devices.size())
            throw std::runtime_error("build-program: no device " + std::to_string(device_index));
        DeviceContext device(devices[size_t(device_index)]);
        if (test_compiler_crash(device_index)) {
            std::signal(SIGSEGV, SIG_DFL);  // past a sanitizer's handler: die of the signal
            std::raise(SIGSEGV);
        }
        cl::Program program = build_program(device.context, device.info.device,
                                            read_text(dir / "source.cl"), read_text(dir / "options"));
        std::vector<unsigned char> binary = program_binary(program, device.info.device);
        if (binary.empty()) throw std::runtime_error("the driver returned no binary");
        const fs::path partial = dir / "binary.partial";
        if (!write_text(partial, std::string(binary.begin(), binary.end())))
            throw std::runtime_error("cannot write " + partial.string());
        fs::rename(partial, dir / "binary");
        return 0;
    } catch (const RuntimeError& e) {  // the build failed: its log for the parent
        write_text(dir / "error", e.what());
        return 3;
    } catch (const std::exception& e) {
        write_text(dir / "error", e.what());
        return 1;
    }
}

}  // namespace mcrt
