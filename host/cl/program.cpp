#include "cl/program.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <tuple>

#include "cl/binary_cache.h"
#include "cl/build_child.h"
#include "cl/cl_error.h"
#include "cl/no_device.h"
#include "common/environment.h"

namespace mcrt {

// On a driver that caches kernels itself (PoCL), the binary is stored at this miss of a variant.
constexpr int kDriverCachesStoreAfterMisses = 3;

// Generated at build time (cmake/embed_kernels.cmake): the library the executable links holds
// kernels/ alone (mcrt_kernels) or with the test and bench kernels (mcrt_test_kernels).
const std::map<std::string, std::string>& embedded_kernel_files();

// The file called `name` under `dir` or one of its folders (kernels/ groups files by concept;
// names are unique, as the build checks for the embedded copies); empty when there is none.
static std::filesystem::path find_kernel_file(const std::string& dir, const std::string& name) {
    std::error_code error;
    std::filesystem::path direct = std::filesystem::path(dir) / name;
    if (std::filesystem::is_regular_file(direct, error)) return direct;
    for (std::filesystem::recursive_directory_iterator it(dir, error), end; !error && it != end;
         it.increment(error))
        if (it->path().filename() == name && it->is_regular_file(error)) return it->path();
    return {};
}

static std::string read_kernel_file(const std::string& name) {
    if (const char* dir = environment(kEnvKernelDir); dir && *dir) {
        const std::filesystem::path path = find_kernel_file(dir, name);
        std::ifstream in(path, std::ios::binary);
        if (path.empty() || !in)
            throw RuntimeError("kernel file not found: " + std::string(dir) + "/" + name);
        std::ostringstream text;
        text << in.rdbuf();
        return text.str();
    }
    const auto& files = embedded_kernel_files();
    auto it = files.find(name);
    if (it == files.end()) throw RuntimeError("kernel file not embedded: " + name);
    return it->second;
}

// `name` as a C string literal for #line.
static std::string quoted(const std::string& name) {
    std::string q = "\"";
    for (char c : name) {
        if (c == '"' || c == '\\') q += '\\';
        q += c == '\n' ? ' ' : c;
    }
    return q + "\"";
}

// Expands `#include "name"` lines; a file already expanded is skipped the second time. A
// replacement (a user's file, checked by render/user_source.h) is passed through verbatim: its
// lines are never read as includes here.
static void expand(const std::string& name, const KernelReplacements& replacements,
                   std::set<std::string>& seen, std::string& out) {
    if (!seen.insert(name).second) return;
    auto replaced = replacements.find(name);
    const std::string shown = replaced != replacements.end() ? replaced->second.name : name;
    out += "#line 1 " + quoted(shown) + "\n";
    if (replaced != replacements.end()) {
        out += replaced->second.text;
        // A last line without its new-line, or ending in a backslash (a splice), still ends
        // before the next file's #line.
        out += out.back() == '\n' ? "\n" : "\n\n";
        return;
    }
    std::istringstream in(read_kernel_file(name));
    std::string line;
    int line_number = 0;
    while (std::getline(in, line)) {
        ++line_number;
        size_t start = line.find_first_not_of(" \t");
        if (start != std::string::npos && line.compare(start, 8, "#include") == 0) {
            size_t open = line.find('"', start);
            size_t close = open == std::string::npos ? open : line.find('"', open + 1);
            if (close != std::string::npos) {
                expand(line.substr(open + 1, close - open - 1), replacements, seen, out);
                out += "#line " + std::to_string(line_number + 1) + " " + quoted(shown) + "\n";
                continue;
            }
        }
        out += line;
        out += '\n';
    }
}

std::string kernel_source(const std::string& file, const KernelReplacements& replacements) {
    std::set<std::string> seen;
    std::string out;
    expand(file, replacements, seen, out);
    return out;
}

cl::Program build_program(const cl::Context& context, const cl::Device& device,
                          const std::string& source, const std::string& options) {
    cl_int status = CL_SUCCESS;
    cl::Program program(context, source, false, &status);
    CL_CHECK_STATUS(status, "clCreateProgramWithSource");
    status = program.build(std::vector<cl::Device>{device}, options.c_str());
    if (status != CL_SUCCESS) {
        std::string log, name;
        program.getBuildInfo(device, CL_PROGRAM_BUILD_LOG, &log);
        device.getInfo(CL_DEVICE_NAME, &name);
        // PoCL with an unusable cache directory fails every build and logs no reason.
        std::string platform;
        cl::Platform(device.getInfo<CL_DEVICE_PLATFORM>()).getInfo(CL_PLATFORM_NAME, &platform);
        const std::string cache = pocl_cache_problem();
        if (!cache.empty() && platform.find("Portable Computing Language") != std::string::npos)
            throw RuntimeError("kernel build failed on '" + name + "': " + cache);
        throw RuntimeError("kernel build failed on '" + name + "' (" + cl_error_name(status) +
                           ", options '" + options + "'):\n" + log);
    }
    return program;
}

std::string device_program_options(const DeviceInfo& device) {
    std::string options;
    // Division and sqrt correctly rounded where the device offers it (OpenCL 1.2 sec. 5.6.4.2;
    // without it they may be 2.5 and 3 ulp off): with contraction off in the sources
    // (shared_types.h) and mcrt's own transcendentals (exact_math.cl), every operation the
    // kernels use rounds as IEEE-754 says, and devices agree bit for bit.
    if (device.single_fp_config & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT)
        options += " -cl-fp32-correctly-rounded-divide-sqrt";
    // Intel's CPU runtime: kernels are not vectorised across work-items there unless
    // MCRT_KERNEL_OPTIONS asks for it (-D MCRT_INTEL_VECTORIZE; kernels/core/shared_types.h says
    // why).
    if (device.platform_name.find("Intel(R) OpenCL") != std::string::npos)
        options += " -D MCRT_INTEL_CPU";
    return options;
}

cl::Program cached_program(const DeviceContext& device, const std::string& file,
                           const std::string& given_options,
                           const KernelReplacements& replacements) {
    const std::string options = given_options + device_program_options(device.info);
    // Keyed by the context handle: the cached program holds a reference to its context, so the
    // handle cannot be freed and reused while the entry exists.
    using Key = std::tuple<cl_context, cl_device_id, std::string, std::string>;
    static std::mutex mutex;
    static std::map<Key, cl::Program> programs;
    const std::string source = kernel_source(file, replacements);
    Key key{device.context(), device.info.device(), source, options};
    std::lock_guard<std::mutex> lock(mutex);
    auto it = programs.find(key);
    if (it != programs.end()) return it->second;
    // Across processes, the on-disk binary cache skips compilation on drivers without their own.
    // PoCL caches compiled kernels itself (unless POCL_KERNEL_CACHE=0), but its hit still
    // preprocesses and hashes the source, which a binary hit skips (docs/BENCHMARKS.md, "Start-up:
    // from the command to the first sample"). Asking PoCL for the binary costs a code generation,
    // so there the binary is stored at a variant's third build only: one built once or twice
    // (most of a test suite's) never pays for it.
    const char* pocl_cache = environment(kEnvPoclKernelCache);
    bool driver_caches =
        device.info.platform_name.find("Portable Computing Language") != std::string::npos &&
        !(pocl_cache && std::string(pocl_cache) == "0");
    // Where the binary is stored at the first build anyway, the build runs in a child process
    // (build_child.h): a vendor compiler's crash then costs the device, not mcrt. PoCL's builds
    // stay in this process: asking it for the binary costs a second code generation.
    const bool in_child = !driver_caches && !build_child_executable().empty();
    cl::Program program =
        build_program_cached(device.context, device.info.device, device.info, source, options,
                             nullptr, driver_caches ? kDriverCachesStoreAfterMisses : 1, in_child);
    programs.emplace(key, program);
    return program;
}

cl::Kernel make_kernel(const cl::Program& program, const char* name) {
    cl_int status = CL_SUCCESS;
    cl::Kernel kernel(program, name, &status);
    CL_CHECK_STATUS(status, (std::string("clCreateKernel(") + name + ")").c_str());
    return kernel;
}

}  // namespace mcrt
