// Runs a child process for the end-to-end tests: argv passed as is (no shell, so arguments
// with spaces survive), stdout and stderr captured through files, killed after a timeout.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace mcrt::test {

// Under AddressSanitizer the sanitizer catches a child's SIGSEGV itself and exits 1 with its
// report; the tests of deaths by a signal let the signal through, as in a release build, so that
// mcrt's supervisor sees the death (children inherit ASAN_OPTIONS).
inline void let_segv_through_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
    const char* old = std::getenv("ASAN_OPTIONS");
    ::setenv("ASAN_OPTIONS", (std::string(old ? old : "") + ":handle_segv=0").c_str(), 1);
#endif
}

struct ProcessResult {
    int exit_code = -1;      // exit status when the child exited, else -1
    int signal = 0;          // the signal that ended the child, else 0
    bool timed_out = false;  // killed by us after the timeout
    std::string out, err;    // everything written to stdout and stderr
    double seconds = 0;

    bool exited() const { return exit_code >= 0; }
};

inline std::string read_whole_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// Lines of `text` that start with `prefix`.
inline std::vector<std::string> lines_starting_with(const std::string& text,
                                                    const std::string& prefix) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line))
        if (line.compare(0, prefix.size(), prefix) == 0) lines.push_back(line);
    return lines;
}

inline std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

// A fresh directory under the system temp directory, removed with everything in it when the
// object goes out of scope.
class TempDir {
  public:
    explicit TempDir(const std::string& tag = "mcrt-test") {
        static std::atomic<unsigned> counter{0};
        auto base = std::filesystem::temp_directory_path();
        for (int attempt = 0; attempt < 1000; ++attempt) {
            auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
            path_ = base / (tag + "-" + std::to_string(getpid()) + "-" + std::to_string(counter++) +
                            "-" + std::to_string(stamp % 1000000007));
            if (std::filesystem::create_directory(path_)) return;
        }
        throw std::runtime_error("cannot create a temporary directory under " + base.string());
    }
    ~TempDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::string operator/(const std::string& name) const { return (path_ / name).string(); }

  private:
    std::filesystem::path path_;
};

// Runs `program` with `args` (argv[0] is the program path), stdin from /dev/null, stdout and
// stderr into files under `scratch`. A child still running after `timeout_seconds` is killed
// with SIGKILL and reported as timed_out. With `send_signal`, that signal is sent to the child
// once, `signal_after` seconds after it started.
inline ProcessResult run_process(const std::string& program, const std::vector<std::string>& args,
                                 const std::filesystem::path& scratch,
                                 double timeout_seconds = 120.0, int send_signal = 0,
                                 double signal_after = 0.0) {
    static std::atomic<unsigned> counter{0};
    unsigned id = counter++;
    std::string out_path = (scratch / ("stdout-" + std::to_string(id) + ".txt")).string();
    std::string err_path = (scratch / ("stderr-" + std::to_string(id) + ".txt")).string();

    std::vector<std::string> storage;
    storage.reserve(args.size() + 1);
    storage.push_back(program);
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : storage) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);

    auto start = std::chrono::steady_clock::now();
    pid_t pid = 0;
    int rc = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("posix_spawn " + program + ": " + std::strerror(rc));

    ProcessResult result;
    int status = 0;
    for (;;) {
        pid_t done = waitpid(pid, &status, WNOHANG);
        if (done == pid) break;
        if (done < 0 && errno != EINTR)
            throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
        double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (send_signal != 0 && elapsed >= signal_after) {
            kill(pid, send_signal);
            send_signal = 0;
        }
        if (elapsed > timeout_seconds) {
            kill(pid, SIGKILL);
            while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            }
            result.timed_out = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
    result.out = read_whole_file(out_path);
    result.err = read_whole_file(err_path);
    std::filesystem::remove(out_path);
    std::filesystem::remove(err_path);
    return result;
}

}  // namespace mcrt::test
