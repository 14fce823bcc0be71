// Why no OpenCL device was found, or a kernel build failed without a log, when the cause is known
// from the environment rather than "no ICD installed".
#pragma once

#include <string>

namespace mcrt {

// Why no device was found, where mcrt can tell: "no OpenCL device found: " and POCL_DEVICES
// naming no device type PoCL has (listing those it has), an unusable PoCL cache directory, or an
// installed implementation that cannot be loaded (dlopen's reason, with the address-space limit);
// else the plain message.
std::string no_device_message();

// Before the ICD loader reads its vendor files (OCL_ICD_VENDORS, else /etc/OpenCL/vendors): throws
// RuntimeError naming an .icd file that it would wait on forever (a FIFO, a device) or crash on
// (ocl-icd 2.3 dies of SIGSEGV on one that starts with a NUL byte).
void check_icd_files();

// "PoCL's kernel cache directory /x/pocl cannot be created (/x is not a directory); set
// POCL_CACHE_DIR to a writable directory", or "" when it is usable. PoCL then finds no device,
// or, with a device already set up, fails every kernel build without a log.
std::string pocl_cache_problem();

}  // namespace mcrt
