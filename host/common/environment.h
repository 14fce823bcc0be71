// Every environment variable mcrt reads, listed once (kEnvironment; docs/DESIGN.md
// "Environment"): what each is for and who sets it. Code reads them only through here.
#pragma once

#include <string>
#include <vector>

namespace mcrt {

enum EnvironmentVariable {
    // Users and scripts.
    kEnvCacheDir,       // MCRT_CACHE_DIR
    kEnvNoKernelCache,  // MCRT_NO_KERNEL_CACHE
    kEnvMpiTimeout,     // MCRT_MPI_TIMEOUT
    kEnvNoSupervisor,   // MCRT_NO_SUPERVISOR
    // Development overrides.
    kEnvKernelDir,      // MCRT_KERNEL_DIR
    kEnvKernelOptions,  // MCRT_KERNEL_OPTIONS
    kEnvBuildChild,     // MCRT_BUILD_CHILD
    // Set by mcrt for its own child process.
    kEnvSupervised,  // MCRT_SUPERVISED
    // Test hooks (common/test_hooks.h).
    kEnvTestPause,           // MCRT_TEST_PAUSE
    kEnvTestPauseSeconds,    // MCRT_TEST_PAUSE_SECONDS
    kEnvTestPauseUntil,      // MCRT_TEST_PAUSE_UNTIL
    kEnvTestNoTmpfile,       // MCRT_TEST_NO_TMPFILE
    kEnvTestWrongDevice,     // MCRT_TEST_WRONG_DEVICE
    kEnvTestCompilerCrash,   // MCRT_TEST_COMPILER_CRASH
    kEnvTestContextFailure,  // MCRT_TEST_CONTEXT_FAILURE
    kEnvFaultInject,         // MCRT_FAULT_INJECT
    kEnvSlowDevice,          // MCRT_SLOW_DEVICE
    // Set by others, read by mcrt.
    kEnvPoclKernelCache,  // POCL_KERNEL_CACHE
    kEnvPoclCacheDir,     // POCL_CACHE_DIR
    kEnvPoclDevices,      // POCL_DEVICES
    kEnvOclIcdVendors,    // OCL_ICD_VENDORS
    kEnvXdgCacheHome,     // XDG_CACHE_HOME
    kEnvHome,             // HOME
    kEnvOmpiWorldSize,    // OMPI_COMM_WORLD_SIZE
    kEnvPmixRank,         // PMIX_RANK
    kEnvPmiRank,          // PMI_RANK
    kEnvPmiSize,          // PMI_SIZE
    kEnvironmentVariableCount
};

struct EnvironmentEntry {
    EnvironmentVariable id;
    const char* name;
    const char* kind;  // "user", "development", "internal", "test hook" or "read"
    const char* description;
};

// One entry per variable, in enum order.
extern const std::vector<EnvironmentEntry> kEnvironment;

// The variable's value; nullptr when it is not set (set and empty is "").
const char* environment(EnvironmentVariable v);

// Its value, "" when it is not set.
std::string environment_value(EnvironmentVariable v);

// Removes the variable from this process's environment (and so from its children's).
void unset_environment(EnvironmentVariable v);

// "D:V" in the variable: device index D and a value, for test hooks that name one device. True
// (and *value) when the variable names device `device`.
bool environment_device_value(EnvironmentVariable v, int device, double* value);

}  // namespace mcrt
