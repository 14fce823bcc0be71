// An on-disk cache of compiled program binaries, so a second start skips compilation on drivers
// that do not cache kernels themselves (docs/BENCHMARKS.md, "Kernel build and start-up").
//
// Entries live in $MCRT_CACHE_DIR if set, else $XDG_CACHE_HOME/mcrt/kernels, else
// $HOME/.cache/mcrt/kernels; MCRT_NO_KERNEL_CACHE=1 turns the cache off. One file per key,
// <32 hex digits of the key>.bin:
//
//   offset  size  field
//        0     8  magic "MCRTBIN1"
//        8    16  key (hi, lo), little-endian
//       24     8  payload size in bytes, little-endian
//       32     8  hash of the payload, little-endian (detects flipped bytes before the driver
//                 sees them: a driver may accept a corrupt binary and run wrong code)
//       40     n  payload: clGetProgramInfo(CL_PROGRAM_BINARIES) for the one device
//
// The cache never makes a build fail: an entry that cannot be read, is corrupt or is rejected
// by the driver is rebuilt from source and overwritten, and an entry that cannot be written is
// skipped.
#pragma once

#include <CL/opencl.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "cl/device.h"

namespace mcrt {

// Bumped whenever the file layout or the key's content changes; part of the key.
constexpr uint32_t kBinaryCacheFormatVersion = 1;

// 128 bits: two unrelated 64-bit hashes (FNV-1a and MurmurHash64A) of the same canonical string.
struct BinaryCacheKey {
    uint64_t hi = 0, lo = 0;
    std::string hex() const;  // 32 lower-case hex digits, hi first
    bool operator==(const BinaryCacheKey& o) const { return hi == o.hi && lo == o.lo; }
    bool operator!=(const BinaryCacheKey& o) const { return !(*this == o); }
};

// Key of the binary of `source` built with `options` for the device: platform name, device
// name, device version, driver version, source, options, kBinaryCacheFormatVersion and the
// vendor compiler's settings from the environment (Intel's CL_CONFIG_* variables, such as
// CL_CONFIG_USE_VECTORIZER, change the code it generates), each length-prefixed so no two
// different field lists give the same string.
BinaryCacheKey binary_cache_key(const DeviceInfo& device, const std::string& source,
                                const std::string& options);

// The cache directory from the environment (see the top of this file); empty when the cache is
// disabled or no directory can be named (no HOME).
std::string binary_cache_directory();

// Writes `binary` as the entry for `key` at `path` atomically, creating the directory tree;
// returns why it could not (empty on success). Never throws: a cache must not fail a render.
std::string store_binary_cache_entry(const std::string& path, const BinaryCacheKey& key,
                                     const std::vector<unsigned char>& binary);

// What build_program_cached did.
struct BuildReport {
    bool cache_hit = false;       // built from a cached binary
    double seconds = 0;           // wall time of the whole call
    std::string path;             // the entry's file; empty when the cache is disabled
    std::string rejected;         // why an existing entry was not used (corrupt, driver refused)
    std::string store_error;      // why the entry could not be written; empty when written or hit
    bool store_deferred = false;  // a miss counted, not stored (store_after_misses)
};

// The program of `source` built with `options` for `device` (a device of `context`): from the
// cached binary when there is a valid one, else built from source (build_program: a failing
// build throws RuntimeError with the build log) and its binary stored for the next start: at
// once when store_after_misses is 1, else only at the store_after_misses-th miss of the key
// (counted in <key>.misses beside the entry). For a driver whose own cache makes a rebuild
// cheap and asking for the binary dear (PoCL generates the code again: docs/BENCHMARKS.md,
// "Start-up"), a variant built once or twice never pays for a binary that would not be read.
// With `in_child`, the build from source runs in a child process (build_child.h), so that a
// compiler crash costs the build (CompilerCrash), not the process.
cl::Program build_program_cached(const cl::Context& context, const cl::Device& device,
                                 const DeviceInfo& info, const std::string& source,
                                 const std::string& options, BuildReport* report = nullptr,
                                 int store_after_misses = 1, bool in_child = false);

// The built program from `binary`, or a null program with `why` set; never throws.
cl::Program program_from_binary(const cl::Context& context, const cl::Device& device,
                                const std::vector<unsigned char>& binary,
                                const std::string& options, std::string& why);

// The binary of `program` for `device`, empty when the driver gives none.
std::vector<unsigned char> program_binary(const cl::Program& program, const cl::Device& device);

}  // namespace mcrt
