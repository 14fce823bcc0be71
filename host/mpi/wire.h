// The bytes of the messages between the ranks of one render (docs/MPI.md "How it works"). Native
// byte order and sizes: every rank runs the same build of mcrt on the same kind of machine.
// Pure serialization, no MPI, so that it is tested in every build.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "render/accumulator.h"
#include "render/work_queue.h"
#include "scene/gltf_import.h"

namespace mcrt::wire {

using Bytes = std::vector<unsigned char>;

// Rank 0 → every rank, by broadcast: the files of the scene and the text of --estimator-file.
Bytes encode_inputs(const FileBundle& files, const std::string& estimator_source);
void decode_inputs(const Bytes& bytes, FileBundle& files, std::string& estimator_source);

// Rank r → rank 0, once set up: where it runs, the devices it renders with (index, name), and
// the warnings of its setup (rank 0 prints them; the other ranks print nothing).
struct Hello {
    std::string host;
    std::vector<std::pair<int, std::string>> devices;
    std::vector<std::string> warnings;
};
Bytes encode_hello(const Hello& hello);
Hello decode_hello(const Bytes& bytes);

// Rank 0 → one device of rank r: the next work item, or nothing (stop: the render is over).
// 40 bytes.
Bytes encode_item(const std::optional<WorkItem>& item);
std::optional<WorkItem> decode_item(const Bytes& bytes);

// That device → rank 0: the item's per-run sums (gpu::ChunkSums, 64 bytes per pixel, chunk and
// replicate) with what the report needs, or the error that retired the device. 80 bytes of
// header + 64 bytes per run: 4 bytes per sample with one replicate.
struct ResultMessage {
    bool failed = false;
    std::string error;            // when failed
    uint64_t target_samples = 0;  // what the device's next item should hold
    uint64_t samples = 0;         // samples of this item
    double seconds_busy = 0;      // its kernel time
    double seconds_run = 0;       // the item's wall time on that rank (kernels and read-back)
    BatchResult result;           // result.item is the item sent
};
Bytes encode_result(const ResultMessage& message);
// Checks that the sums are those of `item` (the item this device was sent).
ResultMessage decode_result(const Bytes& bytes, const WorkItem& item);

}  // namespace mcrt::wire
