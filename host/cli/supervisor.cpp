#include "cli/supervisor.h"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <vector>

#include "common/environment.h"
#include "common/signal_name.h"
#include "common/stop_signals.h"

extern char** environ;

namespace mcrt {

namespace {

using Clock = std::chrono::steady_clock;

// The worker's end of the pipe; -1 in a process without a supervisor.
int g_report_fd = -1;

// The supervisor's: the stop signal caught and not yet handled, and the count of them.
volatile std::sig_atomic_t g_signal = 0;
volatile std::sig_atomic_t g_signals = 0;

extern "C" void on_stop_signal(int sig) {
    g_signal = sig;
    g_signals = g_signals + 1;
}

// A terminal's Ctrl-Z (SIGTSTP), which reaches the supervisor's process group alone.
volatile std::sig_atomic_t g_terminal_stop = 0;
extern "C" void on_terminal_stop(int) { g_terminal_stop = 1; }
bool g_terminal_stop_caught = false;

// Only so that a child's exit interrupts poll(2) at once.
extern "C" void on_child(int) {}

// Set when this process is continued after a stop (SIGSTOP from outside, a batch system
// suspending the job, Ctrl-Z): the time it was stopped does not count against the grace periods.
volatile std::sig_atomic_t g_continued = 0;
extern "C" void on_continue(int) { g_continued = 1; }

void catch_terminal_stop() {
    struct sigaction action {};
    action.sa_handler = on_terminal_stop;
    sigemptyset(&action.sa_mask);
    sigaction(SIGTSTP, &action, nullptr);
}

// The stop signals whose handler the supervisor installed (not those it found ignored).
bool g_caught[NSIG] = {};

// Catches the stop signals. SIGINT and SIGTERM always, as the render's interrupt guard does
// (a shell script's `mcrt render ... &` starts with SIGINT ignored, and `kill -INT` still stops
// it); SIGHUP unless it is ignored (nohup), which the worker then inherits across exec.
void catch_stop_signals() {
    for (int sig : kStopSignals) {
        struct sigaction old {};
        sigaction(sig, nullptr, &old);
        if (sig == SIGHUP && old.sa_handler == SIG_IGN) continue;
        struct sigaction action {};
        action.sa_handler = on_stop_signal;
        sigemptyset(&action.sa_mask);
        sigaction(sig, &action, nullptr);
        g_caught[sig] = true;
    }
    struct sigaction tstp {};
    sigaction(SIGTSTP, nullptr, &tstp);
    if (tstp.sa_handler != SIG_IGN) {  // ignored where no shell does job control
        catch_terminal_stop();
        g_terminal_stop_caught = true;
    }
    struct sigaction child {};
    child.sa_handler = on_child;
    child.sa_flags = SA_NOCLDSTOP;
    sigemptyset(&child.sa_mask);
    sigaction(SIGCHLD, &child, nullptr);
    struct sigaction resumed {};
    resumed.sa_handler = on_continue;
    sigemptyset(&resumed.sa_mask);
    sigaction(SIGCONT, &resumed, nullptr);
}

// The caught stop signals to `action` (SIG_DFL: the next one ends the supervisor, and with it
// the worker; SIG_IGN: the outputs are complete).
void set_stop_signals(void (*action)(int)) {
    for (int sig : kStopSignals)
        if (g_caught[sig]) std::signal(sig, action);
}

// The worker's stage, as its lines name it (report_to_supervisor).
enum class Stage { kSetup, kLaunch, kServe, kWriting, kDone };

// What the worker last said.
struct WorkerStage {
    std::string command;  // render, devices, bench or integrate
    Stage stage = Stage::kSetup;
    double time_limit = 0;
    bool bar = false;
    Clock::time_point launched;
    std::string estimator;
    int rank = 0;
};

void take_line(const std::string& line, WorkerStage& w) {
    std::istringstream in(line);
    std::string word;
    in >> word;
    if (word == "estimator") {
        w.estimator = line.size() > 10 ? line.substr(10) : "";
    } else if (word == "rank") {
        in >> w.rank;
    } else if (word == "launch") {
        int bar = 0;
        in >> w.time_limit >> bar;
        w.bar = bar != 0;
        w.stage = Stage::kLaunch;
        w.launched = Clock::now();
    } else if (word == "serve") {
        w.stage = Stage::kServe;
    } else if (word == "writing") {
        w.stage = Stage::kWriting;
    } else if (word == "done") {
        w.stage = Stage::kDone;
        set_stop_signals(SIG_IGN);  // as the worker does (common/stop_signals.h)
    }
}

// Reads what the pipe holds now; false at its end.
bool read_reports(int fd, std::string& pending, WorkerStage& w) {
    char buffer[512];
    for (;;) {
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n == 0) return false;
        if (n < 0) return errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK;
        pending.append(buffer, size_t(n));
        for (size_t end; (end = pending.find('\n')) != std::string::npos;) {
            take_line(pending.substr(0, end), w);
            pending.erase(0, end + 1);
        }
    }
}

std::string seconds_text(double s) {
    std::ostringstream out;
    out << s;
    return out.str();
}

// "with the estimator file F (HINT)" or "(OTHER)".
std::string estimator_hint(const WorkerStage& w, const std::string& hint,
                           const std::string& other) {
    return w.estimator.empty() ? " (" + other + ")"
                               : " with the estimator file " + w.estimator + " (" + hint + ")";
}

void print_error(const WorkerStage& w, const std::string& message) {
    // The progress bar's line is left open while kernels run.
    std::cerr << (w.stage == Stage::kLaunch && w.bar ? "\n" : "")
              << "mcrt: error: " << (w.rank > 0 ? "rank " + std::to_string(w.rank) + ": " : "")
              << message << std::endl;
}

// Where a worker that did not stop within the grace period (`of_what`: after what) was stuck.
std::string stuck_where(const WorkerStage& w, const std::string& of_what) {
    const std::string grace = seconds_text(kSupervisorGraceSeconds) + " s" + of_what;
    if (w.stage == Stage::kLaunch)
        return "a launch on the devices did not return within " + grace +
               estimator_hint(w, "an estimator that does not return?",
                              "a kernel or an OpenCL driver that does not return");
    if (w.command != "render")  // devices, bench, integrate: no stage reported
        return "mcrt " + w.command + " did not stop within " + grace +
               " (an OpenCL driver or kernel that does not return?)";
    return "the render did not stop within " + grace +
           " while setting up (loading the scene, building kernels, waiting for other ranks)";
}

// Why a worker died of `sig`, where it was.
std::string death_where(const WorkerStage& w) {
    if (w.stage == Stage::kLaunch || w.stage == Stage::kServe)
        return std::string("while the devices ran the kernels") +
               estimator_hint(w, "user code that writes out of bounds, or a large private array?",
                              "a fault in mcrt's kernels or in the OpenCL driver");
    if (w.stage == Stage::kWriting) return "while writing the outputs (a bug in mcrt)";
    return "while setting up the render: loading the scene, building kernels (a bug in mcrt or "
           "in the OpenCL driver)";
}

void kill_and_reap(pid_t pid, int* status) {
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, status, 0) < 0 && errno == EINTR) {
    }
}

// What a death of a command other than render was: it lists the OpenCL platforms, and bench and
// integrate build and run kernels, in the worker, where a crashing ICD loader or driver (a broken
// .icd file, a driver setting it cannot take) ends the process with no word of its own.
std::string command_death(const WorkerStage& w, const std::string& how) {
    return "mcrt " + w.command + " " + how +
           " in the OpenCL driver, its ICD loader or mcrt (check the .icd files that "
           "OCL_ICD_VENDORS or /etc/OpenCL/vendors name, and the driver's environment variables "
           "such as POCL_*; `MCRT_NO_SUPERVISOR=1` runs it in one process for a debugger)";
}

// How the supervisor ends once the worker has: with its status, or one line for its death.
int outcome(int status, const WorkerStage& w) {
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (!WIFSIGNALED(status)) return 1;
    const int sig = WTERMSIG(status);
    if (sig == SIGINT || sig == SIGTERM || sig == SIGHUP) {
        // Ended by a stop signal's own action before the render caught it (the one forwarded, or
        // one sent to the worker itself): end the same way, as one process would have.
        std::signal(sig, SIG_DFL);
        std::raise(sig);
        return 128 + sig;
    }
    if (w.command != "render") {
        print_error(w, command_death(w, sig == SIGKILL ? "was killed (SIGKILL: out of memory?)"
                                                       : "died of " + signal_name(sig)));
        return 1;
    }
    if (w.stage == Stage::kDone) {
        std::cerr << "mcrt: warning: "
                  << (w.rank > 0 ? "rank " + std::to_string(w.rank) + ": " : "")
                  << "the render died of " << signal_name(sig)
                  << " after its outputs were complete; they are whole" << std::endl;
        return 0;
    }
    if (sig == SIGKILL)
        print_error(w, "the render was killed (SIGKILL: out of memory?) " + death_where(w) +
                           "; no image was written");
    else
        print_error(w, "the render died of " + signal_name(sig) + " " + death_where(w) +
                           "; no image was written");
    return 1;
}

// Waits for the worker, forwarding stop signals and holding it to them and to its time limit.
int supervise(const std::string& command, pid_t pid, int fd) {
    WorkerStage w;
    w.command = command;
    std::string pending;
    int forwarded = 0;
    Clock::time_point forwarded_at;
    auto seconds_since = [](Clock::time_point t) {
        return std::chrono::duration<double>(Clock::now() - t).count();
    };
    // Time stopped (this process or the worker: SIGSTOP, a suspended job, Ctrl-Z) moves the
    // grace periods' starts on; a stopped worker is not stuck in a launch. The time limit itself
    // is wall-clock time: the worker, continued after it, ends at its next check with what is
    // done (ROBUSTNESS.md "Kernels that hang or crash").
    Clock::time_point last_tick = Clock::now();
    bool worker_stopped = false;
    Clock::time_point worker_stopped_at;
    auto pause_for = [&](Clock::duration paused) {
        forwarded_at += paused;
        w.launched += paused;
    };
    for (;;) {
        struct pollfd p = {fd, POLLIN, 0};
        if (::poll(&p, 1, 50) > 0 && fd >= 0 && !read_reports(fd, pending, w)) {
            ::close(fd);
            fd = -1;  // at its end: poll(2) ignores a negative descriptor
        }
        const Clock::time_point now = Clock::now();
        if (g_continued) {  // this process was stopped since the last tick
            g_continued = 0;
            pause_for(now - last_tick);
        }
        last_tick = now;
        int status = 0;
        const pid_t done = ::waitpid(pid, &status, WNOHANG | WUNTRACED | WCONTINUED);
        if (done == pid && WIFSTOPPED(status)) {
            if (!worker_stopped) worker_stopped = true, worker_stopped_at = now;
        } else if (done == pid && WIFCONTINUED(status)) {
            if (worker_stopped) pause_for(now - worker_stopped_at);
            worker_stopped = false;
        } else if (done == pid) {
            if (fd >= 0) read_reports(fd, pending, w);
            return outcome(status, w);
        }
        if (done < 0 && errno != EINTR) return 1;  // not ours any more: nothing to wait for

        if (const int sig = g_signal; sig != 0) {
            g_signal = 0;
            if (fd >= 0) read_reports(fd, pending, w);  // a "done" written before the signal
            if (w.stage == Stage::kDone || w.stage == Stage::kServe) {
                // Ignored, as the worker ignores it.
            } else if (forwarded == 0) {
                ::kill(pid, sig);  // its interrupt guard stops the render and writes what is done
                if (worker_stopped) {  // a stopped worker cannot stop: it goes on to do so
                    ::kill(pid, SIGCONT);
                    pause_for(now - worker_stopped_at);
                    worker_stopped = false;
                }
                forwarded = sig;
                forwarded_at = now;
                set_stop_signals(SIG_DFL);  // a second signal ends both at once
            } else {
                // A second one that came before the handlers were reset.
                kill_and_reap(pid, &status);
                std::signal(sig, SIG_DFL);
                std::raise(sig);
                return 128 + sig;
            }
        }
        if (g_terminal_stop) {
            // Ctrl-Z: the worker stops with this process and goes on with it (POSIX job
            // control); the time it was stopped does not count (g_continued, above).
            g_terminal_stop = 0;
            ::kill(pid, SIGSTOP);
            // SIGSTOP, not SIGTSTP: in an orphaned process group (a child of a test runner, a
            // daemon) the kernel discards SIGTSTP's default stop (POSIX job control), which
            // would leave the worker stopped and this process running. Returns once continued
            // (fg, bg, SIGCONT); a shell sees the same stopped job either way.
            std::raise(SIGSTOP);
            ::kill(pid, SIGCONT);
            continue;
        }
        if (worker_stopped) continue;  // stopped from outside: nothing runs that could be stuck
        if (forwarded != 0 && w.stage != Stage::kWriting && w.stage != Stage::kDone &&
            seconds_since(forwarded_at) > kSupervisorGraceSeconds) {
            kill_and_reap(pid, &status);
            print_error(
                w, "stopped by " + signal_abbreviation(forwarded) + ", but " + stuck_where(w, "") +
                       (w.command == "render" ? "; no image was written" : "; it was killed"));
            return 1;
        }
        if (w.stage == Stage::kLaunch && w.time_limit > 0 &&
            seconds_since(w.launched) > w.time_limit + kSupervisorGraceSeconds) {
            kill_and_reap(pid, &status);
            print_error(w, "the time limit of " + seconds_text(w.time_limit) + " s passed, but " +
                               stuck_where(w, " of it") + "; no image was written");
            return 1;
        }
    }
}

// The commands that touch OpenCL, each run in a supervised worker: render (kernels that hang or
// crash), and devices, bench and integrate (an ICD loader or driver that crashes while listing
// the platforms or building and running their kernels).
bool is_supervised_command(const char* name) {
    for (const char* command : {"render", "devices", "bench", "integrate"})
        if (std::strcmp(name, command) == 0) return true;
    return false;
}

// The worker's side: ends with its supervisor, and reports on the pipe it was given.
void become_worker(const char* text) {
    int fd = -1;
    long parent = 0;
    const bool parsed = std::sscanf(text, "%d,%ld", &fd, &parent) == 2;
    unset_environment(kEnvSupervised);  // not for the worker's own children
    if (!parsed) return;
    // A worker without its supervisor would run unwatched: it ends with it (prctl(2)).
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != pid_t(parent)) std::raise(SIGKILL);  // it ended before the prctl
    if (fd > 2 && ::fcntl(fd, F_SETFD, FD_CLOEXEC) == 0) g_report_fd = fd;
    // The worker is in a process group of its own, in the background as the terminal sees it:
    // with `stty tostop` its progress bar would stop it (POSIX write(): an ignored SIGTTOU lets
    // the write through).
    std::signal(SIGTTOU, SIG_IGN);
}

}  // namespace

void report_to_supervisor(const std::string& line) {
    if (g_report_fd < 0) return;
    std::string text = line;
    for (char& c : text)
        if (c == '\n') c = '?';
    text += '\n';
    // One write(2) of fewer than PIPE_BUF bytes is atomic; a supervisor gone is EPIPE (SIGPIPE
    // is ignored).
    if (text.size() > 512) text = text.substr(0, 511) + '\n';
    ssize_t ignored = ::write(g_report_fd, text.data(), text.size());
    (void)ignored;
}

std::optional<int> supervise_command(int argc, char** argv) {
    if (const char* supervised = environment(kEnvSupervised)) {
        become_worker(supervised);
        return std::nullopt;
    }
    if (argc < 2 || !is_supervised_command(argv[1])) return std::nullopt;
    const std::string opt_out = environment_value(kEnvNoSupervisor);
    if (environment(kEnvNoSupervisor) && opt_out != "0") return std::nullopt;
    std::error_code ec;
    if (std::filesystem::read_symlink("/proc/self/exe", ec).empty() || ec) return std::nullopt;

    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) return std::nullopt;
    // Above the standard descriptors: with stdout closed (`mcrt devices >&-`) the pipe would
    // otherwise become the worker's stdout, and what it prints would go to this process.
    for (int& end : fds)
        if (end <= STDERR_FILENO) {
            const int moved = ::fcntl(end, F_DUPFD_CLOEXEC, STDERR_FILENO + 1);
            ::close(end);
            end = moved;
        }
    if (fds[0] < 0 || fds[1] < 0) {
        for (int end : fds)
            if (end >= 0) ::close(end);
        return std::nullopt;
    }
    ::fcntl(fds[0], F_SETFL, O_NONBLOCK);
    ::fcntl(fds[1], F_SETFD, 0);  // the worker's end stays open across exec

    std::vector<std::string> env_storage;
    const std::string name = kEnvironment[size_t(kEnvSupervised)].name;
    for (char** e = environ; *e; ++e)
        if (std::strncmp(*e, (name + "=").c_str(), name.size() + 1) != 0)
            env_storage.emplace_back(*e);
    env_storage.push_back(name + "=" + std::to_string(fds[1]) + "," + std::to_string(::getpid()));
    std::vector<char*> envp;
    for (std::string& e : env_storage) envp.push_back(e.data());
    envp.push_back(nullptr);

    catch_stop_signals();  // before the spawn: a signal then is forwarded once the worker exists
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    // Its own process group: a terminal's Ctrl-C reaches the supervisor alone, which forwards it
    // once. SIGINT and SIGTERM at their default actions (a forwarded one ends a worker that has
    // not caught it yet); SIGHUP as it was (ignored under nohup).
    posix_spawnattr_setflags(
        &attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    posix_spawnattr_setpgroup(&attributes, 0);
    sigset_t none, defaults;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attributes, &none);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    pid_t pid = 0;
    const int spawned =
        posix_spawn(&pid, "/proc/self/exe", nullptr, &attributes, argv, envp.data());
    posix_spawnattr_destroy(&attributes);
    ::close(fds[1]);
    if (spawned != 0) {  // render in this process, as without a supervisor
        ::close(fds[0]);
        for (int sig : kStopSignals)
            if (g_caught[sig]) std::signal(sig, SIG_DFL), g_caught[sig] = false;
        std::signal(SIGCHLD, SIG_DFL);
        std::signal(SIGCONT, SIG_DFL);
        if (g_terminal_stop_caught) std::signal(SIGTSTP, SIG_DFL);
        if (const int sig = g_signal; sig != 0) std::raise(sig);
        return std::nullopt;
    }
    return supervise(argv[1], pid, fds[0]);
}

}  // namespace mcrt
