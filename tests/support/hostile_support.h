// Child processes for the hostile-input tests: extra environment variables, stdout and stderr
// into a pipe whose reader is gone, waiting for a line on stderr before signalling.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "process_support.h"

namespace mcrt::test {

class Child {
  public:
    // Starts `args` (argv[0] first) with `env` added to the environment; stdout and stderr go to
    // `err_file`, or, with `closed_pipe`, to a pipe whose read end is already closed.
    Child(const std::vector<std::string>& args, const std::vector<std::string>& env,
          const std::string& err_file, bool closed_pipe = false) {
        std::vector<std::string> storage = args;
        std::vector<char*> argv;
        for (std::string& a : storage) argv.push_back(a.data());
        argv.push_back(nullptr);
        std::vector<std::string> env_storage = env;
        std::vector<char*> envp;
        for (char** e = environ; *e; ++e) envp.push_back(*e);
        for (std::string& e : env_storage) envp.push_back(e.data());
        envp.push_back(nullptr);

        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        int fds[2] = {-1, -1};
        if (closed_pipe) {
            if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
            ::close(fds[0]);  // nobody will read: writes get EPIPE / SIGPIPE
            posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
            posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
        } else {
            posix_spawn_file_actions_addopen(&actions, 1, err_file.c_str(),
                                             O_WRONLY | O_CREAT | O_TRUNC, 0644);
            posix_spawn_file_actions_adddup2(&actions, 1, 2);
        }
        const int rc =
            posix_spawn(&pid_, storage[0].c_str(), &actions, nullptr, argv.data(), envp.data());
        posix_spawn_file_actions_destroy(&actions);
        if (fds[1] >= 0) ::close(fds[1]);
        if (rc != 0) throw std::runtime_error("posix_spawn: " + std::string(std::strerror(rc)));
        err_file_ = err_file;
    }
    ~Child() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            int status = 0;
            ::waitpid(pid_, &status, 0);
        }
    }

    // Waits until the output file holds `text`; false when the child ended or `seconds` passed.
    bool wait_for_text(const std::string& text, double seconds) {
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
        while (std::chrono::steady_clock::now() < end) {
            if (read_whole_file(err_file_).find(text) != std::string::npos) return true;
            int status = 0;
            if (::waitpid(pid_, &status, WNOHANG) == pid_) {
                pid_ = -1;
                status_ = status;
                return read_whole_file(err_file_).find(text) != std::string::npos;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        return false;
    }

    void signal(int sig) const {
        if (pid_ > 0) ::kill(pid_, sig);
    }

    // Waits for the end (killing it after `seconds`); the wait status.
    int wait(double seconds) {
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
        while (pid_ > 0) {
            int status = 0;
            if (::waitpid(pid_, &status, WNOHANG) == pid_) {
                pid_ = -1;
                status_ = status;
                break;
            }
            if (std::chrono::steady_clock::now() > end) {
                ::kill(pid_, SIGKILL);
                ::waitpid(pid_, &status, 0);
                pid_ = -1;
                status_ = status;
                timed_out_ = true;
                break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        return status_;
    }
    bool timed_out() const { return timed_out_; }
    pid_t pid() const { return pid_; }

    // The process that renders: `mcrt render` runs in a child of the supervisor (the pid this
    // object started, host/cli/supervisor.h); its only child, read from /proc/PID/task/PID/children
    // (proc(5)), or the pid itself when it has none.
    pid_t render_pid() const {
        std::istringstream children(read_whole_file("/proc/" + std::to_string(pid_) + "/task/" +
                                                    std::to_string(pid_) + "/children"));
        pid_t child = 0;
        return children >> child ? child : pid_;
    }

    // Waits until the child no longer catches `sig` (its SA_RESETHAND handler ran), reading
    // SigCgt in /proc/PID/status; false after `seconds`.
    bool wait_handler_reset(int sig, double seconds) const {
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
        while (std::chrono::steady_clock::now() < end) {
            std::istringstream status(read_whole_file("/proc/" + std::to_string(pid_) + "/status"));
            std::string line;
            while (std::getline(status, line)) {
                if (line.rfind("SigCgt:", 0) != 0) continue;
                const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
                if (!(mask & (1ull << (sig - 1)))) return true;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        return false;
    }
    std::string output() const { return read_whole_file(err_file_); }

  private:
    pid_t pid_ = -1;
    int status_ = 0;
    bool timed_out_ = false;
    std::string err_file_;
};

}  // namespace mcrt::test
