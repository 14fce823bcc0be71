// OpenCL program sources (embedded or from disk) and their compilation.
#pragma once

#include <CL/opencl.hpp>
#include <map>
#include <string>

#include "cl/device.h"

namespace mcrt {

// A kernel file's text supplied by the caller instead of the embedded one (a user's estimator):
// `name` is what build errors call it (#line markers), e.g. the path the user gave.
struct KernelFile {
    std::string name;
    std::string text;
};
using KernelReplacements = std::map<std::string, KernelFile>;  // by the file name #include uses

// Source of the kernel file `file` (by name, in whichever folder of kernels/) with every #include
// "..." expanded once (include guards are not needed) and #line markers, so build errors name the
// right file and line. The files are those embedded at build time, or those of $MCRT_KERNEL_DIR
// when set (development override), except those in `replacements`. Throws RuntimeError when a file
// is missing.
std::string kernel_source(const std::string& file, const KernelReplacements& replacements = {});

// Builds source for the context's device with the options. A failing build throws
// RuntimeError carrying the device name and the build log.
cl::Program build_program(const cl::Context& context, const cl::Device& device,
                          const std::string& source, const std::string& options);

// The build options every program gets on this device, after its own: the arithmetic that makes
// devices agree bit for bit, and workarounds for a vendor's compiler.
std::string device_program_options(const DeviceInfo& device);

// build_program(kernel_source(file), options + device_program_options) for the device, built once
// per process and kept: every specialised variant (-D options) is compiled once, however many
// renders use it. Thread-safe.
cl::Program cached_program(const DeviceContext& device, const std::string& file,
                           const std::string& options, const KernelReplacements& replacements = {});

// A kernel by name, throwing ClError.
cl::Kernel make_kernel(const cl::Program& program, const char* name);

}  // namespace mcrt
