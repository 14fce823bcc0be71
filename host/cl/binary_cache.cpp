// Compiled program binaries on disk, keyed by device, driver, source and options.
#include "cl/binary_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>  // environ

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <system_error>
#include <thread>
#include <vector>

#include "cl/build_child.h"
#include "cl/cl_error.h"
#include "cl/pocl_binary.h"
#include "cl/program.h"
#include "common/atomic_file.h"
#include "common/environment.h"
#include "common/error.h"

namespace mcrt {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'M', 'C', 'R', 'T', 'B', 'I', 'N', '1'};
constexpr size_t kHeaderBytes = 40;

// FNV-1a, 64 bits (Fowler, Noll, Vo; http://www.isthe.com/chongo/tech/comp/fnv/).
uint64_t fnv1a_64(const unsigned char* data, size_t n) {
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i < n; ++i) {
        h ^= data[i];
        h *= 1099511628211ull;
    }
    return h;
}

uint64_t load_le64(const unsigned char* p) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}

void store_le64(unsigned char* p, uint64_t v) {
    for (int i = 0; i < 8; ++i) p[i] = (unsigned char)(v >> (8 * i));
}

// MurmurHash64A (Austin Appleby, public domain), reading bytes little-endian on every host.
uint64_t murmur64a(const unsigned char* data, size_t n, uint64_t seed) {
    const uint64_t m = 0xc6a4a7935bd1e995ull;
    const int r = 47;
    uint64_t h = seed ^ (n * m);
    size_t blocks = n / 8;
    for (size_t i = 0; i < blocks; ++i) {
        uint64_t k = load_le64(data + 8 * i);
        k *= m;
        k ^= k >> r;
        k *= m;
        h ^= k;
        h *= m;
    }
    const unsigned char* tail = data + 8 * blocks;
    switch (n & 7) {
        case 7:
            h ^= uint64_t(tail[6]) << 48;
            [[fallthrough]];
        case 6:
            h ^= uint64_t(tail[5]) << 40;
            [[fallthrough]];
        case 5:
            h ^= uint64_t(tail[4]) << 32;
            [[fallthrough]];
        case 4:
            h ^= uint64_t(tail[3]) << 24;
            [[fallthrough]];
        case 3:
            h ^= uint64_t(tail[2]) << 16;
            [[fallthrough]];
        case 2:
            h ^= uint64_t(tail[1]) << 8;
            [[fallthrough]];
        case 1:
            h ^= uint64_t(tail[0]);
            h *= m;
    }
    h ^= h >> r;
    h *= m;
    h ^= h >> r;
    return h;
}

uint64_t payload_hash(const unsigned char* data, size_t n) {
    return murmur64a(data, n, 0x6d637274'62696e31ull);  // "mcrtbin1"
}

void append_field(std::string& out, const char* name, const std::string& value) {
    out += name;
    out += '=';
    out += std::to_string(value.size());
    out += ':';
    out += value;
    out += '\n';
}

bool cache_disabled() {
    const char* off = environment(kEnvNoKernelCache);
    return off && *off && std::strcmp(off, "0") != 0;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What lies at a cache file's name, without following it: the cache directory may be shared or
// planted with links, FIFOs and directories named like entries (ROBUSTNESS.md, "The kernel cache").
enum class CacheName { missing, regular, other };

// Opens `path` for reading when it is a regular file: never through a symbolic link (O_NOFOLLOW)
// and never blocking on a FIFO (O_NONBLOCK). -1 otherwise, with `kind` saying what is there.
int open_cache_file(const std::string& path, CacheName& kind, std::string& what) {
    kind = CacheName::missing;
    const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        if (errno == ENOENT) return -1;
        kind = CacheName::other;
        what = errno == ELOOP ? "a symbolic link" : std::string(std::strerror(errno));
        if (errno == EISDIR) what = "a directory";
        return -1;
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        kind = CacheName::other;
        what = S_ISDIR(st.st_mode)    ? "a directory"
               : S_ISFIFO(st.st_mode) ? "a FIFO"
               : S_ISSOCK(st.st_mode) ? "a socket"
                                      : "a device or special file";
        ::close(fd);
        return -1;
    }
    kind = CacheName::regular;
    return fd;
}

// Removes what is not a regular file at a cache file's name, so that the cache heals: a link,
// FIFO, socket or device node loses its name only (unlink(2) never touches what a link points
// to), an empty directory is removed; "" on success, else why the name stays.
std::string clear_cache_name(const std::string& path, const std::string& what) {
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) return errno == ENOENT ? "" : std::strerror(errno);
    if (S_ISREG(st.st_mode)) return "";
    if (S_ISDIR(st.st_mode)) {
        if (::rmdir(path.c_str()) == 0) return "";
        return path + " is a directory that is not empty (" + std::strerror(errno) +
               "); remove it to let the cache store this entry";
    }
    if (::unlink(path.c_str()) == 0) return "";
    return path + " is " + what + " that cannot be removed: " + std::strerror(errno);
}

// The whole of a regular file at `path` (not through a link, not a FIFO); false with `why` set
// when something else is there (and cleared away, see clear_cache_name) or it cannot be read.
bool read_cache_file(const std::string& path, std::string& bytes, std::string& why) {
    bytes.clear();
    CacheName kind;
    std::string what;
    const int fd = open_cache_file(path, kind, what);
    if (fd < 0) {
        if (kind == CacheName::missing) return false;  // a plain miss
        why = "not a regular file but " + what;
        const std::string stays = clear_cache_name(path, what);
        why += stays.empty() ? " (removed)" : "; " + stays;
        return false;
    }
    char buffer[65536];
    for (;;) {
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n == 0) break;
        if (n < 0) {
            if (errno == EINTR) continue;
            why = "read error: " + std::string(std::strerror(errno));
            ::close(fd);
            return false;
        }
        bytes.append(buffer, size_t(n));
    }
    ::close(fd);
    return true;
}

// Writes `bytes` to a cache file: a new temporary beside it (O_EXCL | O_NOFOLLOW: never an
// existing file or a link's target), renamed onto the name. rename(2) replaces a link, FIFO or
// device node at the name itself, never what a link points to; a directory there is cleared
// first (clear_cache_name) or the store fails with the reason.
void write_cache_file(const std::string& path, const std::string& bytes) {
    static std::atomic<unsigned> counter{0};
    sweep_stale_temporaries(path);  // those of writers killed before their rename
    const fs::path target(path);
    const std::string temporary =
        (target.parent_path() / ("." + target.filename().string() + ".tmp-" +
                                 std::to_string(::getpid()) + "-" + std::to_string(counter++)))
            .string();
    const int fd =
        ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) throw RuntimeError(temporary + ": cannot create: " + std::strerror(errno));
    size_t written = 0;
    while (written < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int error = n < 0 ? errno : EIO;
            ::close(fd);
            ::unlink(temporary.c_str());
            throw RuntimeError(temporary + ": cannot write: " + std::strerror(error));
        }
        written += size_t(n);
    }
    if (::close(fd) != 0) {
        const int error = errno;
        ::unlink(temporary.c_str());
        throw RuntimeError(temporary + ": cannot write: " + std::strerror(error));
    }
    struct stat st {};
    if (::lstat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
        const std::string stays = clear_cache_name(path, "a directory");
        if (!stays.empty()) {
            ::unlink(temporary.c_str());
            throw RuntimeError(stays);
        }
    }
    if (::rename(temporary.c_str(), path.c_str()) != 0) {
        const int error = errno;
        ::unlink(temporary.c_str());
        throw RuntimeError(path +
                           ": cannot rename the new entry into place: " + std::strerror(error));
    }
}

// The payload of a valid entry for `key`, or an empty vector with `why` set.
std::vector<unsigned char> read_entry(const std::string& path, const BinaryCacheKey& key,
                                      std::string& why) {
    std::string bytes;
    if (!read_cache_file(path, bytes, why)) return {};  // a plain miss when `why` stays empty
    const std::vector<unsigned char> file(bytes.begin(), bytes.end());
    if (file.size() < kHeaderBytes) {
        why = "truncated header";
        return {};
    }
    if (std::memcmp(file.data(), kMagic, sizeof kMagic) != 0) {
        why = "wrong magic";
        return {};
    }
    if (load_le64(&file[8]) != key.hi || load_le64(&file[16]) != key.lo) {
        why = "wrong key";
        return {};
    }
    uint64_t size = load_le64(&file[24]);
    if (size == 0 || size != file.size() - kHeaderBytes) {
        why = "payload size " + std::to_string(size) + " but " +
              std::to_string(file.size() - kHeaderBytes) + " bytes present";
        return {};
    }
    if (load_le64(&file[32]) != payload_hash(&file[kHeaderBytes], size)) {
        why = "payload hash mismatch";
        return {};
    }
    return std::vector<unsigned char>(file.begin() + kHeaderBytes, file.end());
}

// The environment's compiler settings of the OpenCL implementations whose binaries this cache
// holds, sorted: Intel's CPU runtime reads CL_CONFIG_* (its vectoriser among them) when it builds
// a program, so a binary built under one setting is not the binary of another. (PoCL's programs
// do not come through this cache: it keeps its own.)
std::string compiler_environment() {
    std::vector<std::string> entries;
    for (char** e = environ; e && *e; ++e)
        if (std::strncmp(*e, "CL_CONFIG_", 10) == 0) entries.emplace_back(*e);
    std::sort(entries.begin(), entries.end());
    std::string joined;
    for (const std::string& entry : entries) joined += entry + "\n";
    return joined;
}

}  // namespace

// The built program from `binary`, or a null program with `why` set; never throws.
cl::Program program_from_binary(const cl::Context& context, const cl::Device& device,
                                const std::vector<unsigned char>& binary,
                                const std::string& options, std::string& why) {
    cl_int status = CL_SUCCESS;
    std::vector<cl_int> binary_status;
    cl::Program program(context, std::vector<cl::Device>{device}, cl::Program::Binaries{binary},
                        &binary_status, &status);
    if (status != CL_SUCCESS) {
        why = "clCreateProgramWithBinary: " + cl_error_name(status);
        return cl::Program();
    }
    // clBuildProgram is required for a program created from a binary, too (OpenCL 1.2 §5.6.2).
    status = program.build(std::vector<cl::Device>{device}, options.c_str());
    if (status != CL_SUCCESS) {
        why = "clBuildProgram from binary: " + cl_error_name(status);
        return cl::Program();
    }
    return program;
}

// The binary of `program` for `device`, empty when the driver gives none.
std::vector<unsigned char> program_binary(const cl::Program& program, const cl::Device& device) {
    std::vector<cl::Device> devices;
    std::vector<std::vector<unsigned char>> binaries;
    if (program.getInfo(CL_PROGRAM_DEVICES, &devices) != CL_SUCCESS) return {};
    if (program.getInfo(CL_PROGRAM_BINARIES, &binaries) != CL_SUCCESS) return {};
    for (size_t i = 0; i < devices.size() && i < binaries.size(); ++i)
        if (devices[i]() == device()) return std::move(binaries[i]);
    return {};
}

std::string BinaryCacheKey::hex() const {
    char text[33];
    std::snprintf(text, sizeof text, "%016llx%016llx", (unsigned long long)hi,
                  (unsigned long long)lo);
    return text;
}

BinaryCacheKey binary_cache_key(const DeviceInfo& device, const std::string& source,
                                const std::string& options) {
    std::string canonical = "mcrt kernel binary\n";
    append_field(canonical, "format", std::to_string(kBinaryCacheFormatVersion));
    append_field(canonical, "platform", device.platform_name);
    append_field(canonical, "device", device.name);
    append_field(canonical, "device_version", device.version);
    append_field(canonical, "driver_version", device.driver_version);
    append_field(canonical, "options", options);
    append_field(canonical, "source", source);
    append_field(canonical, "compiler_environment", compiler_environment());
    const auto* bytes = reinterpret_cast<const unsigned char*>(canonical.data());
    return {fnv1a_64(bytes, canonical.size()),
            murmur64a(bytes, canonical.size(), 0x9e3779b97f4a7c15ull)};
}

std::string binary_cache_directory() {
    if (cache_disabled()) return {};
    if (const char* dir = environment(kEnvCacheDir); dir && *dir) return dir;
    if (const char* xdg = environment(kEnvXdgCacheHome); xdg && *xdg)
        return std::string(xdg) + "/mcrt/kernels";
    if (const char* home = environment(kEnvHome); home && *home)
        return std::string(home) + "/.cache/mcrt/kernels";
    return {};
}

std::string store_binary_cache_entry(const std::string& path, const BinaryCacheKey& key,
                                     const std::vector<unsigned char>& binary) {
    if (binary.empty()) return "the driver returned no binary";
    try {
        std::error_code ec;
        fs::create_directories(fs::path(path).parent_path(), ec);
        if (ec)
            return "cannot create " + fs::path(path).parent_path().string() + ": " + ec.message();
        unsigned char header[kHeaderBytes];
        std::memcpy(header, kMagic, sizeof kMagic);
        store_le64(header + 8, key.hi);
        store_le64(header + 16, key.lo);
        store_le64(header + 24, binary.size());
        store_le64(header + 32, payload_hash(binary.data(), binary.size()));
        std::string bytes(reinterpret_cast<const char*>(header), sizeof header);
        bytes.append(reinterpret_cast<const char*>(binary.data()), binary.size());
        write_cache_file(path, bytes);
        return {};
    } catch (const std::exception& e) {
        return e.what();
    }
}

// The misses of a key before this one, from its counter file, and the counter bumped; never
// throws (an unreadable or unwritable counter counts as none: the binary is stored later).
static int count_miss(const std::string& counter) {
    int misses = 0;
    std::string text, why;
    if (read_cache_file(counter, text, why)) {
        std::istringstream in(text);
        if (!(in >> misses) || misses < 0 || misses > 1000000) misses = 0;
    }
    try {
        std::error_code ec;
        fs::create_directories(fs::path(counter).parent_path(), ec);
        write_cache_file(counter, std::to_string(misses + 1) + "\n");
    } catch (const std::exception&) {
    }
    return misses;
}

// From source, in a child process when asked (build_child.h): its binary loaded here.
static cl::Program build_from_source(const cl::Context& context, const cl::Device& device,
                                     const DeviceInfo& info, const std::string& source,
                                     const std::string& options, bool in_child) {
    if (!in_child) return build_program(context, device, source, options);
    std::vector<unsigned char> binary = build_binary_in_child(info, source, options);
    std::string why;
    cl::Program program = program_from_binary(context, device, binary, options, why);
    if (!program())
        throw RuntimeError("device '" + info.name + "' refused the binary its own build made (" +
                           why + ")");
    return program;
}

// The binary of `program`, or, when PoCL serialised it while another process was rewriting its
// cache (pocl_binary.h), the binary of a fresh build of the same source, which PoCL reads from its
// then settled cache: a few tries, a little apart. Empty with `why` set when none is whole.
static std::vector<unsigned char> whole_binary(const cl::Program& program,
                                               const cl::Context& context, const cl::Device& device,
                                               const DeviceInfo& info, const std::string& source,
                                               const std::string& options, bool in_child,
                                               std::string& why) {
    std::vector<unsigned char> binary = program_binary(program, device);
    for (int attempt = 1; attempt <= 3; ++attempt) {
        why = pocl_binary_problem(binary);
        if (why.empty()) return binary;
        std::this_thread::sleep_for(std::chrono::milliseconds(50 * attempt));
        try {
            binary = program_binary(
                build_from_source(context, device, info, source, options, in_child), device);
        } catch (const std::exception& e) {  // the cache never fails a build
            why += "; not stored (its rebuild failed: " + std::string(e.what()) + ")";
            return {};
        }
    }
    why = pocl_binary_problem(binary);
    if (why.empty()) return binary;
    why += "; not stored";
    return {};
}

cl::Program build_program_cached(const cl::Context& context, const cl::Device& device,
                                 const DeviceInfo& info, const std::string& source,
                                 const std::string& options, BuildReport* report,
                                 int store_after_misses, bool in_child) {
    const auto t0 = std::chrono::steady_clock::now();
    BuildReport local;
    BuildReport& r = report ? *report : local;
    r = BuildReport();

    const std::string directory = binary_cache_directory();
    if (directory.empty()) {
        cl::Program program = build_from_source(context, device, info, source, options, in_child);
        r.seconds = seconds_since(t0);
        return program;
    }

    const BinaryCacheKey key = binary_cache_key(info, source, options);
    r.path = (fs::path(directory) / (key.hex() + ".bin")).string();

    // Hit: a valid entry the driver accepts.
    std::vector<unsigned char> binary = read_entry(r.path, key, r.rejected);
    if (!binary.empty()) {
        // PoCL aborts the process on a binary without program.bc rather than refusing it.
        r.rejected = pocl_binary_problem(binary);
        if (!r.rejected.empty()) binary.clear();
    }
    if (!binary.empty()) {
        cl::Program program = program_from_binary(context, device, binary, options, r.rejected);
        if (program()) {
            r.cache_hit = true;
            r.seconds = seconds_since(t0);
            return program;
        }
    }

    // Miss or rejected entry: build from source (a failing build throws) and store the binary,
    // or count the miss while fewer than store_after_misses - 1 came before.
    cl::Program program = build_from_source(context, device, info, source, options, in_child);
    const std::string counter = (fs::path(directory) / (key.hex() + ".misses")).string();
    if (store_after_misses > 1 && count_miss(counter) + 1 < store_after_misses) {
        r.store_deferred = true;
        r.seconds = seconds_since(t0);
        return program;
    }
    std::string problem;
    const std::vector<unsigned char> whole =
        whole_binary(program, context, device, info, source, options, in_child, problem);
    r.store_error = problem.empty() ? store_binary_cache_entry(r.path, key, whole) : problem;
    if (store_after_misses > 1 && r.store_error.empty())
        ::unlink(counter.c_str());  // the name only
    r.seconds = seconds_since(t0);
    return program;
}

}  // namespace mcrt
