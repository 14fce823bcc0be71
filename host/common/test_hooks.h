// Test hooks, all in one place: let the end-to-end tests stop mcrt at a known point (writing an
// output, after the outputs are complete) without timing guesses, and make a device fail, slow
// or wrong. Each is inert unless its environment variable is set (common/environment.h).
#pragma once

#include <cstdint>

namespace mcrt {

// When MCRT_TEST_PAUSE equals `point`, writes "mcrt: test: paused at POINT" to stderr and sleeps
// MCRT_TEST_PAUSE_SECONDS (default 20) seconds, signals notwithstanding, or until the file
// MCRT_TEST_PAUSE_UNTIL exists. Otherwise nothing. Points: "before-write" (the outputs'
// temporaries exist, nothing is written yet), "write" (all written, before the commit),
// "commit" (inside the commit, after the first rename), "commit-wait" (another process holds
// an output directory's lock; this one waits for it next), "exit" (after the command),
// "start-up" (the Python module's mcrt.Context() and mcrt.devices(), before OpenCL starts).
void test_pause(const char* point);

// True when MCRT_TEST_NO_TMPFILE is set: outputs take the named-temporary path that file systems
// without O_TMPFILE get.
bool test_no_tmpfile();

// True when MCRT_TEST_WRONG_DEVICE names device index `device`: its render programs are built
// with -D MCRT_TEST_WRONG_VALUES, which scales every sample by 1 + 2^-20
// (kernels/render/render.cl), a device that computes slightly wrong values for the agreement check
// to catch.
bool test_wrong_device(int device);

// True when MCRT_TEST_COMPILER_CRASH names device index `device`: a child build for it
// (host/cl/build_child.h) dies of SIGSEGV, as Intel's compiler did.
bool test_compiler_crash(int device);

// True when MCRT_TEST_CONTEXT_FAILURE names device index `device`: its context is refused as
// Intel's runtime refuses one with CL_CONFIG_CPU_TARGET_ARCH=junk (CL_DEVICE_NOT_AVAILABLE).
bool test_context_failure(int device);

// The launch (counted from 1) at which device `device` fails, when MCRT_FAULT_INJECT is "D:N"
// for it; 0: never.
uint64_t test_fault_launch(int device);

// How many times slower device `device` reports itself, when MCRT_SLOW_DEVICE is "D:F" for it
// (at least 1); 1 otherwise.
double test_slow_factor(int device);

}  // namespace mcrt
