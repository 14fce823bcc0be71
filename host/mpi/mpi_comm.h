// Point-to-point messages and broadcasts of bytes between the ranks of a render, on
// MPI_COMM_WORLD (built with MPI only).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <optional>

#include "mpi/wire.h"

namespace mcrt::mpi {

// Tags: one hello per rank, then per device slot of a rank its items and its results.
constexpr int kHelloTag = 1;
inline int item_tag(int slot) { return 16 + 2 * slot; }
inline int result_tag(int slot) { return 17 + 2 * slot; }
constexpr int kMaxSlots = 8000;  // MPI guarantees tags up to 32767

void send_bytes(const wire::Bytes& bytes, int dest, int tag);

// Waits for the message from `source` with `tag` and returns it. Waits by polling with short
// sleeps: a blocking MPI receive spins a core, which the PoCL devices on it need.
wire::Bytes receive_bytes(int source, int tag);
// The same, giving up after `seconds`: nothing when no message came by then.
std::optional<wire::Bytes> receive_bytes_within(int source, int tag, double seconds);

// How long rank 0 waits for a rank's hello or an item's result before it takes that rank for
// dead (docs/MPI.md "When a rank dies"): MCRT_MPI_TIMEOUT seconds, 120 by default.
double silence_timeout();

// Rank `root`'s bytes to every rank (in pieces of at most 1 GiB: MPI counts are int).
void broadcast_bytes(wire::Bytes& bytes, int root);
uint64_t broadcast_u64(uint64_t value, int root);

// MPI_Get_processor_name: the host, as MPI names it.
std::string host_name();

}  // namespace mcrt::mpi
