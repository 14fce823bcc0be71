// OpenCL errors: every failing call raises an error naming the call, the code's name and where.
#pragma once

#include <CL/opencl.hpp>
#include <string>

#include "common/error.h"

namespace mcrt {

// "CL_OUT_OF_RESOURCES" for -5, "CL_UNKNOWN_ERROR(-9999)" for codes OpenCL does not define.
std::string cl_error_name(cl_int code);

// An OpenCL call failed; a runtime failure (exit 1).
struct ClError : RuntimeError {
    ClError(const std::string& call, cl_int code, const char* file, int line);
    cl_int code;
};

[[noreturn]] void throw_cl_error(const char* call, cl_int code, const char* file, int line);

}  // namespace mcrt

// Checks the cl_int result of an OpenCL call (C API or Khronos C++ binding without exceptions).
#define CL_CHECK(call)                                                          \
    do {                                                                        \
        cl_int mcrt_cl_status_ = (call);                                        \
        if (mcrt_cl_status_ != CL_SUCCESS)                                      \
            ::mcrt::throw_cl_error(#call, mcrt_cl_status_, __FILE__, __LINE__); \
    } while (0)

// Checks the error out-parameter of a constructor-style call.
#define CL_CHECK_STATUS(status, what)                                                           \
    do {                                                                                        \
        if ((status) != CL_SUCCESS) ::mcrt::throw_cl_error(what, (status), __FILE__, __LINE__); \
    } while (0)
