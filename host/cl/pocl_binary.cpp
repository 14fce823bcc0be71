#include "cl/pocl_binary.h"

#include <cstdint>
#include <cstring>

namespace mcrt {

namespace {

// The layout of PoCL's binary, version 9 (lib/CL/pocl_binary.c, POCLCC_VERSION in PoCL 3.1),
// little-endian:
//   "poclbin\0", device id u64, version u32, kernel count u32, flags u64, root entries u32,
//   build hash (41 bytes);
//   per root entry: its size u64, then files, each (u32 length, relative path) (u32 length,
//   content); the one root entry is the program's "/program.bc";
//   per kernel: its record's size u64 (the whole record, this field included), then the rest.
constexpr char kPoclMagic[8] = {'p', 'o', 'c', 'l', 'b', 'i', 'n', '\0'};
constexpr uint32_t kKnownVersion = 9;
constexpr size_t kBuildHashBytes = 41;

struct Reader {
    const std::vector<unsigned char>& bytes;
    size_t at = 0;
    bool take(size_t n) {
        if (n > bytes.size() - at) return false;
        at += n;
        return true;
    }
    bool u32(uint32_t& v) {
        if (4 > bytes.size() - at) return false;
        v = 0;
        for (int i = 3; i >= 0; --i) v = (v << 8) | bytes[at + size_t(i)];
        at += 4;
        return true;
    }
    bool u64(uint64_t& v) {
        if (8 > bytes.size() - at) return false;
        v = 0;
        for (int i = 7; i >= 0; --i) v = (v << 8) | bytes[at + size_t(i)];
        at += 8;
        return true;
    }
};

}  // namespace

std::string pocl_binary_problem(const std::vector<unsigned char>& binary) {
    if (binary.size() < sizeof kPoclMagic ||
        std::memcmp(binary.data(), kPoclMagic, sizeof kPoclMagic) != 0)
        return {};
    Reader in{binary, sizeof kPoclMagic};
    uint64_t device_id = 0, flags = 0;
    uint32_t version = 0, kernels = 0, roots = 0;
    if (!in.u64(device_id) || !in.u32(version)) return "PoCL binary: truncated header";
    if (version != kKnownVersion) return {};
    if (!in.u32(kernels) || !in.u64(flags) || !in.u32(roots) || !in.take(kBuildHashBytes))
        return "PoCL binary: truncated header";
    if (roots == 0) return "PoCL binary: no program.bc entry";
    for (uint32_t r = 0; r < roots; ++r) {
        uint64_t size = 0;
        if (!in.u64(size)) return "PoCL binary: truncated before root entry " + std::to_string(r);
        if (size == 0)
            return "PoCL binary: root entry " + std::to_string(r) +
                   " (program.bc) is empty: PoCL's cache lost the file while it serialised "
                   "the program";
        if (size > binary.size() - in.at)
            return "PoCL binary: root entry " + std::to_string(r) + " runs past the end";
        const size_t end = in.at + size_t(size);
        bool content = false;
        while (in.at < end) {
            uint32_t path_length = 0, content_length = 0;
            if (!in.u32(path_length) || !in.take(path_length) || !in.u32(content_length) ||
                !in.take(content_length) || in.at > end)
                return "PoCL binary: a file of root entry " + std::to_string(r) +
                       " runs past the entry";
            content = content || content_length > 0;
        }
        if (!content)
            return "PoCL binary: root entry " + std::to_string(r) + " holds no bytes of program.bc";
    }
    if (kernels == 0) return "PoCL binary: no kernels";
    for (uint32_t k = 0; k < kernels; ++k) {
        const size_t start = in.at;
        uint64_t size = 0;
        if (!in.u64(size)) return "PoCL binary: truncated before kernel " + std::to_string(k);
        if (size < 8 || size > binary.size() - start)
            return "PoCL binary: kernel record " + std::to_string(k) + " has size " +
                   std::to_string(size) + " of the " + std::to_string(binary.size() - start) +
                   " bytes left";
        in.at = start + size_t(size);
    }
    if (in.at != binary.size())
        return "PoCL binary: " + std::to_string(binary.size() - in.at) +
               " bytes after the last kernel";
    return {};
}

}  // namespace mcrt
