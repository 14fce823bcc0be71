// The check of a user's estimator file before any compiler sees it (docs/ROBUSTNESS.md, "Estimator
// files"): a lexer of C99's translation phases 1-3 and a walk over the preprocessing directives
// that decides, with three-valued conditions, which regions may be active. No OpenCL: the fuzz
// target runs it alone.
#pragma once

#include <cstddef>
#include <map>
#include <string>

namespace mcrt {

// Private memory the file's function bodies may declare in arrays of constant size, summed over
// all of them (an upper bound of what one call path holds): 64 KiB. mcrt's own kernels hold a few
// KiB (their largest arrays are the BVH traversal stacks of 128 and 260 bytes); a work-item runs
// on a CPU device's worker-thread stack (8 MiB by default on Linux), which a 16 MiB array
// overflows (SIGSEGV). Neither PoCL (1024 for every kernel) nor Intel's CPU runtime (0 for a
// kernel with a 16 MiB array) reports CL_KERNEL_PRIVATE_MEM_SIZE usefully, so the check is static.
constexpr size_t kUserPrivateMemoryLimit = 64 * 1024;

struct UserSource {
    // The text to compile: the file's own, byte for byte, except that each `#include "api.cl"`
    // (already in scope) is blanked to spaces; the same lines, so compiler messages keep them.
    std::string text;
    bool defines_function = false;  // the required function is defined at file scope
    size_t private_bytes = 0;       // constant-size arrays in function bodies, summed (bytes)
    // Each identifier at file scope (brace depth 0) with the line it first appears on: what a
    // build error in mcrt's kernels that names it ("conflicting types for 'render'") points to.
    std::map<std::string, int> file_scope_names;
};

// Checks `text`, the estimator file `name`, and returns what to compile. Throws InputError
// "NAME:LINE: message" (one line) for: a NUL byte; an #include other than the literal
// `#include "api.cl"`, #line, __has_include or any directive but #define, #undef, #if, #ifdef,
// #ifndef, #elif, #else, #endif, #pragma, #error and #warning in a region that may be active;
// an unbalanced conditional; a trigraph that could change the directives; a kernel function;
// recursion among the file's functions (OpenCL C 1.2 sec. 6.9); constant-size arrays over
// kUserPrivateMemoryLimit. `required_function` (e.g. "estimate") only sets defines_function.
UserSource check_user_source(const std::string& name, const std::string& text,
                             const std::string& required_function);

}  // namespace mcrt
