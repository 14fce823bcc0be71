// Reading only regular files: a FIFO blocks forever, a directory reads as garbage or throws
// std::bad_alloc, a device never ends (ROBUSTNESS.md "Inputs that hang or crash the loader").
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace mcrt {

// What a file of mode `mode` is, as a person would say it: "a directory", "a FIFO (named
// pipe)", "a character device", "a block device", "a socket", "a regular file".
std::string file_kind_name(mode_t mode);

// Why `path` cannot be read as a regular file ("no such file", "is a directory", ...), or an
// empty string when it is one (symbolic links followed).
std::string why_not_regular_file(const std::string& path);

// Reads the whole regular file `path` into `out`. Returns false with `why` set ("is a FIFO
// (named pipe); only regular files are read", "larger than 4 GiB", an errno reason) otherwise.
// Opens with O_NONBLOCK so a FIFO swapped in after the check cannot block, and checks the type
// again on the open descriptor.
bool read_regular_file(const std::string& path, std::vector<unsigned char>& out, std::string& why,
                       size_t max_bytes);

}  // namespace mcrt
