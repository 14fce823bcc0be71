// Round trip of one work item between two ranks, through mcrt's own message code
// (host/mpi/mpi_comm.cpp, wire.cpp): rank 0 sends a 40-byte item, rank 1 answers with a result
// of N pixels × 1 chunk; no rendering, so the time is what MPI and the polling wait cost per item.
//
//   mpicxx -O2 -std=c++17 -Ihost -Ikernels bench/mpi_pingpong.cpp host/mpi/mpi_comm.cpp \
//       host/mpi/wire.cpp host/common/environment.cpp -o build/mpi_pingpong
//   mpirun --oversubscribe -n 2 build/mpi_pingpong [PIXELS=12288] [ROUNDS=200]
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "mpi/mpi_comm.h"
#include "mpi/wire.h"

using namespace mcrt;

int main(int argc, char** argv) {
    int provided = 0, rank = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_MULTIPLE, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    const uint32_t pixels = argc > 1 ? uint32_t(std::atoi(argv[1])) : 12288;
    const int rounds = argc > 2 ? std::atoi(argv[2]) : 200;
    WorkItem item{0, 0, 1, 0, pixels};
    if (rank == 0) {
        double total = 0;
        size_t bytes = 0;
        for (int k = 0; k < rounds; ++k) {
            item.seq = uint64_t(k);
            auto start = std::chrono::steady_clock::now();
            mpi::send_bytes(wire::encode_item(item), 1, mpi::item_tag(0));
            wire::Bytes reply = mpi::receive_bytes(1, mpi::result_tag(0));
            wire::ResultMessage m = wire::decode_result(reply, item);
            total +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            bytes = reply.size() + 40;
        }
        mpi::send_bytes(wire::encode_item(std::nullopt), 1, mpi::item_tag(0));
        std::printf("%u pixels: %zu bytes per item, %.3f ms per round trip (%d rounds)\n", pixels,
                    bytes, 1e3 * total / rounds, rounds);
    } else {
        for (;;) {
            auto got = wire::decode_item(mpi::receive_bytes(0, mpi::item_tag(0)));
            if (!got) break;
            wire::ResultMessage m;
            m.result.item = *got;
            m.result.sums.resize(got->pixel_count());
            mpi::send_bytes(wire::encode_result(m), 0, mpi::result_tag(0));
        }
    }
    MPI_Finalize();
}
