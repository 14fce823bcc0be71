#include "mpi/mpi_comm.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <limits>
#include <string>
#include <thread>

#include "common/environment.h"
#include "common/error.h"

namespace mcrt::mpi {
namespace {

void check(int code, const char* call) {
    if (code == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    throw RuntimeError(std::string(call) + ": " + std::string(text, size_t(length)));
}

}  // namespace

void send_bytes(const wire::Bytes& bytes, int dest, int tag) {
    if (bytes.size() > size_t(std::numeric_limits<int>::max()))
        throw RuntimeError("MPI: a message of " + std::to_string(bytes.size()) + " bytes");
    check(MPI_Send(bytes.data(), int(bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD),
          "MPI_Send");
}

std::optional<wire::Bytes> receive_bytes_within(int source, int tag, double seconds) {
    // 20 µs doubling to 1 ms: a reply within a fraction of a millisecond of its arrival, next to
    // items of about 150 ms.
    const auto start = std::chrono::steady_clock::now();
    auto pause = std::chrono::microseconds(20);
    MPI_Message message;
    MPI_Status status;
    for (;;) {
        int found = 0;
        check(MPI_Improbe(source, tag, MPI_COMM_WORLD, &found, &message, &status), "MPI_Improbe");
        if (found) break;
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
            seconds)
            return std::nullopt;
        std::this_thread::sleep_for(pause);
        pause = std::min(pause * 2, decltype(pause)(1000));
    }
    int count = 0;
    check(MPI_Get_count(&status, MPI_BYTE, &count), "MPI_Get_count");
    wire::Bytes bytes(size_t(std::max(count, 0)));
    check(MPI_Mrecv(bytes.data(), count, MPI_BYTE, &message, MPI_STATUS_IGNORE), "MPI_Mrecv");
    return bytes;
}

wire::Bytes receive_bytes(int source, int tag) {
    return *receive_bytes_within(source, tag, std::numeric_limits<double>::infinity());
}

double silence_timeout() {
    const char* text = environment(kEnvMpiTimeout);
    const double seconds = text ? std::atof(text) : 0.0;
    return seconds > 0 ? seconds : 120.0;
}

uint64_t broadcast_u64(uint64_t value, int root) {
    check(MPI_Bcast(&value, 1, MPI_UINT64_T, root, MPI_COMM_WORLD), "MPI_Bcast");
    return value;
}

void broadcast_bytes(wire::Bytes& bytes, int root) {
    const uint64_t size = broadcast_u64(bytes.size(), root);
    bytes.resize(size);
    constexpr uint64_t kPiece = uint64_t(1) << 30;
    for (uint64_t at = 0; at < size; at += kPiece) {
        const int n = int(std::min(kPiece, size - at));
        check(MPI_Bcast(bytes.data() + at, n, MPI_BYTE, root, MPI_COMM_WORLD), "MPI_Bcast");
    }
}

std::string host_name() {
    char name[MPI_MAX_PROCESSOR_NAME];
    int length = 0;
    if (MPI_Get_processor_name(name, &length) != MPI_SUCCESS) return "?";
    return std::string(name, size_t(length));
}

}  // namespace mcrt::mpi
