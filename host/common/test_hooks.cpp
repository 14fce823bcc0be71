#include "common/test_hooks.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

#include "common/environment.h"

namespace mcrt {

void test_pause(const char* point) {
    const char* wanted = environment(kEnvTestPause);
    if (wanted == nullptr || std::strcmp(wanted, point) != 0) return;
    const char* seconds_text = environment(kEnvTestPauseSeconds);
    const double seconds = seconds_text ? std::atof(seconds_text) : 20.0;
    const std::string line = std::string("mcrt: test: paused at ") + point + "\n";
    ssize_t ignored = ::write(STDERR_FILENO, line.data(), line.size());
    (void)ignored;
    // Sleep in slices: a signal's handler interrupts a single long sleep.
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    const char* until = environment(kEnvTestPauseUntil);  // a file the test creates
    while (std::chrono::steady_clock::now() < end) {
        if (until != nullptr && ::access(until, F_OK) == 0) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
}

bool test_no_tmpfile() { return environment(kEnvTestNoTmpfile) != nullptr; }

static bool names_device(EnvironmentVariable variable, int device) {
    const char* text = environment(variable);
    return text != nullptr && *text != '\0' && std::to_string(device) == text;
}

bool test_wrong_device(int device) { return names_device(kEnvTestWrongDevice, device); }

bool test_compiler_crash(int device) { return names_device(kEnvTestCompilerCrash, device); }

bool test_context_failure(int device) { return names_device(kEnvTestContextFailure, device); }

uint64_t test_fault_launch(int device) {
    double launch = 0;
    return environment_device_value(kEnvFaultInject, device, &launch) ? uint64_t(launch) : 0;
}

double test_slow_factor(int device) {
    double factor = 1;
    return environment_device_value(kEnvSlowDevice, device, &factor) ? std::max(1.0, factor) : 1.0;
}

}  // namespace mcrt
