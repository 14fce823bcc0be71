// Reading only regular files: a FIFO blocks forever, a directory reads as garbage or throws
// std::bad_alloc, a device never ends (ROBUSTNESS.md "Inputs that hang or crash the loader").
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mcrt {

// What a file of mode `mode` is, as a person would say it: "a directory", "a FIFO (named
// pipe)", "a character device", "a block device", "a socket", "a regular file".
std::string file_kind_name(mode_t mode);

// Why `path` cannot be read as a regular file ("no such file", "is a directory", ...), or an
// empty string when it is one (symbolic links followed).
std::string why_not_regular_file(const std::string& path);

// What a read accepts, checked from the file's size before a byte is read.
struct FileSizeLimits {
    uint64_t max_bytes = UINT64_MAX;   // a larger file is refused ("holds N bytes, more than ...")
    uint64_t min_bytes = 0;            // a smaller one too ("holds N bytes, fewer than ...")
    uint64_t read_bytes = UINT64_MAX;  // only this many are read from a longer file
};

// Reads the regular file `path` into `out`: all of it, or its first `limits.read_bytes`. Returns
// false with `why` set ("is a FIFO (named pipe); only regular files are read", "holds 3221225472
// bytes, more than the 1073741824 allowed", an errno reason) otherwise. Opens with O_NONBLOCK so
// a FIFO swapped in after the check cannot block, and checks the type and size again on the open
// descriptor.
bool read_regular_file(const std::string& path, std::vector<unsigned char>& out, std::string& why,
                       const FileSizeLimits& limits);

}  // namespace mcrt
