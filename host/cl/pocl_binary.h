// A check of PoCL's program binaries (clGetProgramInfo(CL_PROGRAM_BINARIES) on PoCL) before
// mcrt stores or loads one.
//
// PoCL makes that binary by reading its own kernel cache directory back from disk
// (pocl_binary_serialize in lib/CL/pocl_binary.c, PoCL 3.1). Another process that builds the
// same program from a cold cache at the same moment rewrites the directory's program.bc: it
// removes the file, writes a temporary, fdatasyncs it and renames it into place
// (pocl_write_file with dont_rewrite 0). A binary serialised inside that window holds an empty
// program.bc entry, and clBuildProgram on it aborts the process inside PoCL
// (pocl_binary_get_kernels_metadata: Assertion `len > 0' failed). docs/ROBUSTNESS.md, "Every
// OpenCL implementation", tells the story.
#pragma once

#include <string>
#include <vector>

namespace mcrt {

// Why `binary`, a PoCL binary of layout version 9 (PoCL 3.x), is not whole: an empty or
// missing program.bc, an empty kernel record, or records that run past its end. Empty when it
// is whole, and when it is not a PoCL binary or of a layout this check does not know (another
// driver's binaries are not judged here).
std::string pocl_binary_problem(const std::vector<unsigned char>& binary);

}  // namespace mcrt
