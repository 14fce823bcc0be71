#include "common/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace mcrt {

std::string file_kind_name(mode_t mode) {
    if (S_ISREG(mode)) return "a regular file";
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

namespace {

std::string refusal(mode_t mode) {
    return "is " + file_kind_name(mode) + "; only regular files are read";
}

}  // namespace

std::string why_not_regular_file(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        return errno == ENOENT ? std::string("no such file") : std::string(std::strerror(errno));
    }
    return S_ISREG(st.st_mode) ? std::string() : refusal(st.st_mode);
}

bool read_regular_file(const std::string& path, std::vector<unsigned char>& out, std::string& why,
                       const FileSizeLimits& limits) {
    why = why_not_regular_file(path);
    if (!why.empty()) return false;
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        why = std::strerror(errno);
        return false;
    }
    struct stat st {};
    bool ok = ::fstat(fd, &st) == 0;
    const uint64_t size = ok ? static_cast<uint64_t>(st.st_size) : 0;
    if (!ok) {
        why = std::strerror(errno);
    } else if (!S_ISREG(st.st_mode)) {
        why = refusal(st.st_mode);
        ok = false;
    } else if (size > limits.max_bytes) {
        why = "holds " + std::to_string(size) + " bytes, more than the " +
              std::to_string(limits.max_bytes) + " allowed";
        ok = false;
    } else if (size < limits.min_bytes) {
        why = "holds " + std::to_string(size) + " bytes, fewer than the " +
              std::to_string(limits.min_bytes) + " declared";
        ok = false;
    }
    if (ok) {
        out.resize(static_cast<size_t>(std::min(size, limits.read_bytes)));
        size_t done = 0;
        while (done < out.size()) {
            const ssize_t n = ::read(fd, out.data() + done, out.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) {
                why = std::strerror(errno);
                ok = false;
                break;
            }
            if (n == 0) break;  // shrank while reading: keep what is there
            done += static_cast<size_t>(n);
        }
        out.resize(done);
    }
    ::close(fd);
    return ok;
}

}  // namespace mcrt
