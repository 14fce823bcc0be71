// Program builds in a child process: a vendor's compiler that crashes (Intel's vectoriser did, on
// most render variants) or runs for minutes then costs that device's build, not mcrt's process,
// and a stop signal ends the wait at once. The child is mcrt's hidden `build-program` subcommand
// (the mcrt executable beside, or above, the running one); it builds the source for one device
// and hands back the binary, which the parent loads and the binary cache keeps.
#pragma once

#include <csignal>
#include <string>
#include <vector>

#include "cl/device.h"
#include "common/error.h"
#include "common/stop_signals.h"

namespace mcrt {

// The compiler died (by a signal, or without a word): the device cannot build this variant.
struct CompilerCrash : RuntimeError {
    using RuntimeError::RuntimeError;
};

// The mcrt executable that runs child builds; empty when none is found (builds then run in
// this process).
const std::string& build_child_executable();

// The program's binary for the device, built by a child process. Throws RuntimeError with the
// build log as build_program does when the source does not build, CompilerCrash when the child
// dies, and RuntimeError when a stop flag (set_build_stop_flag) is raised while it builds (the
// child is killed).
std::vector<unsigned char> build_binary_in_child(const DeviceInfo& device,
                                                 const std::string& source,
                                                 const std::string& options);

// A flag that a signal handler raises to stop the render: child builds watch it.
void set_build_stop_flag(const StopFlag* flag);

// The child's side: `mcrt build-program DIR DEVICE_INDEX` builds DIR/source.cl with the options
// in DIR/options for the device and writes DIR/binary, or the error to DIR/error (exit 3 for a
// build error, 1 for anything else).
int run_build_program_child(const std::string& dir, int device_index);

}  // namespace mcrt
