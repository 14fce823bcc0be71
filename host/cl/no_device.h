// Why no OpenCL device was found, when the cause is known: PoCL finds no device at all when it
// cannot create its kernel cache directory, which is not "no ICD installed".
#pragma once

#include <string>

namespace mcrt {

// "no OpenCL device found: PoCL's kernel cache directory /x/pocl cannot be created (Not a
// directory); set POCL_CACHE_DIR to a writable directory", or the plain message when the cache
// directory is usable.
std::string no_device_message();

}  // namespace mcrt
