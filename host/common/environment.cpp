#include "common/environment.h"

#include <cstdio>
#include <cstdlib>

namespace mcrt {

const std::vector<EnvironmentEntry> kEnvironment = {
    {kEnvCacheDir, "MCRT_CACHE_DIR", "user",
     "where compiled kernels are cached on drivers without a cache of their own (default "
     "$XDG_CACHE_HOME/mcrt or ~/.cache/mcrt)"},
    {kEnvNoKernelCache, "MCRT_NO_KERNEL_CACHE", "user",
     "set and not 0: build every kernel afresh (no binary cache read or written)"},
    {kEnvMpiTimeout, "MCRT_MPI_TIMEOUT", "user",
     "seconds an MPI rank may stay silent before it is taken for lost (default 120)"},
    {kEnvNoSupervisor, "MCRT_NO_SUPERVISOR", "user",
     "set and not 0: render in this process, without the supervising parent process (debugging)"},
    {kEnvKernelDir, "MCRT_KERNEL_DIR", "development",
     "read the kernel sources from this directory instead of the embedded copies"},
    {kEnvKernelOptions, "MCRT_KERNEL_OPTIONS", "development",
     "extra build options for the render program (the stage profiler's -D switches; "
     "-D MCRT_INTEL_VECTORIZE vectorises kernels on Intel's runtime)"},
    {kEnvBuildChild, "MCRT_BUILD_CHILD", "development",
     "the executable that builds programs in a child process; empty: build in this process"},
    {kEnvSupervised, "MCRT_SUPERVISED", "internal",
     "FD,PID: this process is the render of the supervising mcrt PID, reporting on pipe FD"},
    {kEnvTestPause, "MCRT_TEST_PAUSE", "test hook",
     "pause at a named point (before-write, write, exit) so a test can act there"},
    {kEnvTestPauseSeconds, "MCRT_TEST_PAUSE_SECONDS", "test hook",
     "how long MCRT_TEST_PAUSE sleeps (default 20)"},
    {kEnvTestPauseUntil, "MCRT_TEST_PAUSE_UNTIL", "test hook",
     "a file whose appearance ends the pause early"},
    {kEnvTestNoTmpfile, "MCRT_TEST_NO_TMPFILE", "test hook",
     "outputs take the named-temporary path of file systems without O_TMPFILE"},
    {kEnvTestWrongDevice, "MCRT_TEST_WRONG_DEVICE", "test hook",
     "device D computes every sample 1 + 2^-20 too large (the agreement check's test)"},
    {kEnvTestCompilerCrash, "MCRT_TEST_COMPILER_CRASH", "test hook",
     "device D's child build dies of SIGSEGV, as a vendor's compiler can"},
    {kEnvTestContextFailure, "MCRT_TEST_CONTEXT_FAILURE", "test hook",
     "device D's context is refused (CL_DEVICE_NOT_AVAILABLE), as a driver can refuse one"},
    {kEnvFaultInject, "MCRT_FAULT_INJECT", "test hook",
     "D:N: device D fails at its N-th launch (a device lost mid-render)"},
    {kEnvSlowDevice, "MCRT_SLOW_DEVICE", "test hook",
     "D:F: device D reports itself F times slower than it is (scheduling of unequal devices)"},
    {kEnvPoclKernelCache, "POCL_KERNEL_CACHE", "read",
     "PoCL's own switch: 0 turns its kernel cache off, and mcrt then caches binaries itself"},
    {kEnvPoclCacheDir, "POCL_CACHE_DIR", "read", "where PoCL caches kernels (mcrt reports it)"},
    {kEnvPoclDevices, "POCL_DEVICES", "read",
     "the PoCL device types to create (mcrt names the unknown ones when no device is found)"},
    {kEnvOclIcdVendors, "OCL_ICD_VENDORS", "read",
     "the ICD loader's vendor files (mcrt names an implementation that cannot be loaded)"},
    {kEnvXdgCacheHome, "XDG_CACHE_HOME", "read", "the base of the default cache directories"},
    {kEnvHome, "HOME", "read", "the base of the default cache directories without XDG_CACHE_HOME"},
    {kEnvOmpiWorldSize, "OMPI_COMM_WORLD_SIZE", "read",
     "set by Open MPI's mpirun: mcrt joins the MPI job"},
    {kEnvPmixRank, "PMIX_RANK", "read", "set by PMIx launchers (srun): mcrt joins the MPI job"},
    {kEnvPmiRank, "PMI_RANK", "read", "set by PMI launchers: mcrt joins the MPI job"},
    {kEnvPmiSize, "PMI_SIZE", "read", "set by PMI launchers: mcrt joins the MPI job"},
};

const char* environment(EnvironmentVariable v) { return std::getenv(kEnvironment[size_t(v)].name); }

std::string environment_value(EnvironmentVariable v) {
    const char* text = environment(v);
    return text ? text : "";
}

void unset_environment(EnvironmentVariable v) { ::unsetenv(kEnvironment[size_t(v)].name); }

bool environment_device_value(EnvironmentVariable v, int device, double* value) {
    const char* text = environment(v);
    if (!text) return false;
    int d = -1;
    double x = 0;
    if (std::sscanf(text, "%d:%lf", &d, &x) != 2 || d != device) return false;
    *value = x;
    return true;
}

}  // namespace mcrt
