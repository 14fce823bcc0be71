#include "common/test_hooks.h"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

namespace mcrt {

void test_pause(const char* point) {
    const char* wanted = std::getenv("MCRT_TEST_PAUSE");
    if (wanted == nullptr || std::strcmp(wanted, point) != 0) return;
    const char* seconds_text = std::getenv("MCRT_TEST_PAUSE_SECONDS");
    const double seconds = seconds_text ? std::atof(seconds_text) : 20.0;
    const std::string line = std::string("mcrt: test: paused at ") + point + "\n";
    ssize_t ignored = ::write(STDERR_FILENO, line.data(), line.size());
    (void)ignored;
    // Sleep in slices: a signal's handler interrupts a single long sleep.
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    const char* until = std::getenv("MCRT_TEST_PAUSE_UNTIL");  // a file the test creates
    while (std::chrono::steady_clock::now() < end) {
        if (until != nullptr && ::access(until, F_OK) == 0) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
}

bool test_no_tmpfile() { return std::getenv("MCRT_TEST_NO_TMPFILE") != nullptr; }

static bool names_device(const char* variable, int device) {
    const char* text = std::getenv(variable);
    return text != nullptr && *text != '\0' && std::to_string(device) == text;
}

bool test_wrong_device(int device) { return names_device("MCRT_TEST_WRONG_DEVICE", device); }

bool test_compiler_crash(int device) { return names_device("MCRT_TEST_COMPILER_CRASH", device); }

}  // namespace mcrt
