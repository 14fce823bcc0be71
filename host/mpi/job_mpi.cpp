// A render across the ranks of an MPI job (docs/MPI.md): the session, rank 0's RenderJob and the
// other ranks' serve_render. Message by message:
//   1. rank 0 → all (broadcast): a status (0 = go, else rank 0's exit status: stop now), then
//      the scene's files and the estimator's text;
//   2. each rank → 0: a hello (host, the devices it set up, its warnings);
//   3. per device slot: rank 0 → r an item or a stop; r → 0 the item's sums or its failure;
//   4. rank 0 → all (broadcast): the command's exit status.
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <thread>

#include "bvh/bvh.h"
#include "cl/device_select.h"
#include "common/environment.h"
#include "common/error.h"
#include "common/stop_signals.h"
#include "mpi/job.h"
#include "mpi/mpi_comm.h"
#include "mpi/remote_worker.h"
#include "mpi/wire.h"
#include "render/device_worker.h"
#include "render/session.h"
#include "render/variants.h"

namespace mcrt {
namespace {

int g_rank = 0, g_size = 1;
bool g_joined = false;

bool launched_by_mpi() {
    for (EnvironmentVariable v : {kEnvOmpiWorldSize, kEnvPmixRank, kEnvPmiRank, kEnvPmiSize})
        if (environment(v)) return true;
    return false;
}

}  // namespace

JobSession::JobSession() {
    if (!launched_by_mpi()) return;
    int provided = MPI_THREAD_SINGLE;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided) != MPI_SUCCESS) {
        std::fprintf(stderr, "mcrt: error: MPI_Init_thread failed\n");
        std::exit(1);
    }
    g_joined = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    // Every rank's device threads send and receive at once.
    if (g_size > 1 && provided < MPI_THREAD_MULTIPLE) {
        if (g_rank == 0)
            std::fprintf(stderr,
                         "mcrt: error: the MPI library does not support "
                         "MPI_THREAD_MULTIPLE, which a render across ranks needs\n");
        MPI_Finalize();
        std::exit(1);
    }
}

JobSession::~JobSession() {
    if (g_joined) MPI_Finalize();
}

int job_rank() { return g_rank; }
int job_size() { return g_size; }

namespace {

// A rank's reading of its command line on the wire: the usage error (empty when none), then each
// entry, each followed by a NUL (command-line arguments hold none).
std::string encode_command(const std::vector<std::string>& command, const std::string& refused) {
    std::string bytes = refused + '\0';
    for (const std::string& entry : command) bytes += entry + '\0';
    return bytes;
}

std::vector<std::string> decode_command(const std::string& bytes, std::string& refused) {
    std::vector<std::string> parts;
    for (size_t at = 0; at < bytes.size();) {
        const size_t end = bytes.find('\0', at);
        parts.push_back(bytes.substr(at, end == std::string::npos ? std::string::npos : end - at));
        at = end == std::string::npos ? bytes.size() : end + 1;
    }
    refused = parts.empty() ? "" : parts.front();
    if (!parts.empty()) parts.erase(parts.begin());
    return parts;
}

// Why rank `rank`'s reading (`command`, `refused`) is not rank 0's (`root`); "" when it is.
std::string disagreement(int rank, const std::vector<std::string>& command,
                         const std::string& refused, const std::vector<std::string>& root) {
    const std::string who = "rank " + std::to_string(rank);
    if (!refused.empty())
        return who + " refused its command line: " + refused +
               " (every rank must be given rank 0's options)";
    if (command.empty() || root.empty() || command.front() != root.front())
        return who + " runs " + (command.empty() ? "another command" : command.front()) +
               ", rank 0 " + (root.empty() ? "another" : root.front()) +
               ": every rank of a job runs rank 0's command";
    for (size_t i = 1; i < std::max(command.size(), root.size()); ++i) {
        const std::string mine = i < command.size() ? command[i] : "nothing more";
        const std::string its = i < root.size() ? root[i] : "nothing more";
        if (mine != its)
            return who + " was started with " + mine + ", rank 0 with " + its +
                   ": every rank renders with rank 0's options (only --device may differ)";
    }
    return "";
}

}  // namespace

int agree_on_command(const std::vector<std::string>& command, const std::string& refused) {
    if (!g_joined || g_size < 2) return 0;
    const std::string mine = encode_command(command, refused);
    // Gathered as bytes; MPI counts are int, and a command line is far below 2 GiB.
    const int length = int(std::min<size_t>(mine.size(), size_t(1) << 30));
    std::vector<int> lengths(size_t(g_rank == 0 ? g_size : 0));
    MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<int> offsets(lengths.size());
    std::string all;
    if (g_rank == 0) {
        size_t total = 0;
        for (size_t r = 0; r < lengths.size(); ++r) {
            offsets[r] = int(total);
            total += size_t(lengths[r]);
        }
        all.resize(total);
    }
    MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
                0, MPI_COMM_WORLD);
    uint64_t status = 0;
    if (g_rank == 0) {
        if (!refused.empty()) status = 2;  // rank 0's caller prints its own usage error
        for (int r = 1; r < g_size && status == 0; ++r) {
            std::string its_refusal;
            const std::vector<std::string> its = decode_command(
                all.substr(size_t(offsets[size_t(r)]), size_t(lengths[size_t(r)])), its_refusal);
            const std::string why = disagreement(r, its, its_refusal, command);
            if (why.empty()) continue;
            std::fprintf(stderr, "mcrt: error: %s\n", why.c_str());
            std::fflush(stderr);
            status = 2;
        }
    }
    return int(mpi::broadcast_u64(status, 0));
}

// ---------------------------------------------------------------------------------------------
// Rank 0
// ---------------------------------------------------------------------------------------------

struct RenderJob::State {
    bool inputs_sent = false, hellos_received = false, finished = false;
    std::vector<std::string> hosts;
    std::vector<RankTraffic> traffic;  // per rank; RemoteWorkers count into it

    // Every other rank's hello; the workers for their devices go to `workers`.
    void receive_hellos(const std::function<void(const std::string&)>& warn,
                        std::vector<std::unique_ptr<RenderWorker>>& workers) {
        for (int r = 1; r < g_size; ++r) {
            std::optional<wire::Bytes> bytes =
                mpi::receive_bytes_within(r, mpi::kHelloTag, mpi::silence_timeout());
            if (!bytes) {
                traffic[size_t(r)].lost = true;
                if (warn)
                    warn("rank " + std::to_string(r) + " sent no hello within " +
                         std::to_string(int(mpi::silence_timeout())) +
                         " s and is taken for dead; rendering without it");
                continue;
            }
            const wire::Hello hello = wire::decode_hello(*bytes);
            hosts[size_t(r)] = hello.host;
            const std::string who = "rank " + std::to_string(r) + " (" + hello.host + ")";
            for (const std::string& w : hello.warnings)
                if (warn) warn(who + ": " + w);
            if (hello.devices.empty() && warn)
                warn(who + " renders nothing: none of its devices could be set up");
            for (size_t slot = 0; slot < hello.devices.size(); ++slot)
                workers.push_back(std::make_unique<RemoteWorker>(
                    r, int(slot), hello.devices[slot].first, hello.devices[slot].second,
                    &traffic[size_t(r)]));
        }
        hellos_received = true;
    }
};

RenderJob::RenderJob() : state_(std::make_unique<State>()) {
    state_->hosts.assign(size_t(g_size), "");
    state_->hosts[0] = mpi::host_name();
    state_->traffic.resize(size_t(g_size));
}

RenderJob::~RenderJob() {
    try {
        finish(1);  // no-op after finish(); else the other ranks are not left waiting
    } catch (const std::exception&) {
    }
}

void RenderJob::share_inputs(const FileBundle& files, const std::string& estimator_source) {
    wire::Bytes bytes = wire::encode_inputs(files, estimator_source);
    mpi::broadcast_u64(0, 0);  // go
    mpi::broadcast_bytes(bytes, 0);
    state_->inputs_sent = true;
}

RemoteWorkers RenderJob::remote_workers(std::function<void(const std::string&)> warn) {
    return [this, warn] {
        std::vector<std::unique_ptr<RenderWorker>> workers;
        state_->receive_hellos(warn, workers);
        return workers;
    };
}

nlohmann::json RenderJob::ranks_json(const std::vector<DeviceReport>& devices) const {
    nlohmann::json ranks = nlohmann::json::array();
    for (int r = 0; r < g_size; ++r) {
        int count = 0, retired = 0;
        uint64_t samples = 0, items = 0;
        double busy = 0;
        for (const DeviceReport& d : devices) {
            if (d.rank != r) continue;
            ++count;
            retired += d.retired ? 1 : 0;
            samples += d.samples;
            items += d.batches;
            busy += d.seconds_busy;
        }
        const RankTraffic& t = state_->traffic[size_t(r)];
        ranks.push_back({{"rank", r},
                         {"host", state_->hosts[size_t(r)]},
                         {"devices", count},
                         {"devices_retired", retired},
                         {"samples", samples},
                         {"items", items},
                         {"seconds_busy", busy},
                         {"message_bytes", t.bytes},
                         {"seconds_message_overhead", t.seconds_overhead}});
    }
    return ranks;
}

void RenderJob::finish(int status, const std::string& error) {
    State& s = *state_;
    if (s.finished) return;
    s.finished = true;
    for (int r = 1; r < g_size; ++r)
        if (s.traffic[size_t(r)].lost) {
            // A dead rank takes no part in a collective: rank 0 has written what it could, and
            // ends the job (every rank, and mpirun's status) the only way MPI leaves.
            if (!error.empty()) std::fprintf(stderr, "mcrt: error: %s\n", error.c_str());
            std::fprintf(stderr, "mcrt: warning: rank %d was lost; ending the job with MPI_Abort\n",
                         r);
            std::fflush(stderr);
            MPI_Abort(MPI_COMM_WORLD, status == 0 ? 3 : status);
        }
    if (!s.inputs_sent) {
        mpi::broadcast_u64(uint64_t(status == 0 ? 1 : status), 0);  // stop before any work
        return;
    }
    if (!s.hellos_received) {
        // Rank 0 failed before its render started: stop every device the others set up.
        std::vector<std::unique_ptr<RenderWorker>> workers;
        s.receive_hellos({}, workers);
    }  // else the RemoteWorkers told their devices when render() destroyed them
    mpi::broadcast_u64(uint64_t(status), 0);
}

// ---------------------------------------------------------------------------------------------
// The other ranks
// ---------------------------------------------------------------------------------------------

namespace {

// One device's loop: items from rank 0 until a stop; a failure is sent back and ends it.
void serve_device(RenderWorker& worker, int slot) {
    for (;;) {
        const std::optional<WorkItem> item =
            wire::decode_item(mpi::receive_bytes(0, mpi::item_tag(slot)));
        if (!item) return;
        wire::ResultMessage m;
        try {
            const uint64_t samples = worker.report.samples;
            const double busy = worker.report.seconds_busy;
            auto start = std::chrono::steady_clock::now();
            m.result = worker.run(*item);
            m.seconds_run =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            worker.commit_report();
            m.samples = worker.report.samples - samples;
            m.seconds_busy = worker.report.seconds_busy - busy;
            m.target_samples = worker.target_samples();
        } catch (const std::exception& e) {
            m = wire::ResultMessage{};
            m.failed = true;
            m.error = e.what();
        }
        mpi::send_bytes(wire::encode_result(m), 0, mpi::result_tag(slot));
        if (m.failed) return;
    }
}

}  // namespace

int serve_render(const std::function<RenderRequest()>& make_request,
                 const std::vector<std::string>& device_names) {
    // Rank 0 decides when the render stops (its signals, its time limit) and tells every rank;
    // mpirun's SIGTERM to all ranks at Ctrl-C (or a SIGHUP) must not end this one before rank 0 has
    // the samples it is rendering.
    for (int sig : kStopSignals) std::signal(sig, SIG_IGN);

    const uint64_t go = mpi::broadcast_u64(0, 0);
    if (go != 0) return int(go);
    wire::Bytes bytes;
    mpi::broadcast_bytes(bytes, 0);

    wire::Hello hello;
    hello.host = mpi::host_name();
    auto warn = [&](const std::string& w) { hello.warnings.push_back(w); };
    // The rank renders as rank 0 does: its scene loaded into a session (render/session.h) that
    // owns the devices, their programs and the scene's buffers on them.
    std::unique_ptr<RenderSession> session;
    std::shared_ptr<SessionScene> scene;
    RenderPlan plan;
    try {
        FileBundle files;
        RenderRequest r = make_request();  // rank 0 made the same one: it said go
        wire::decode_inputs(bytes, files, r.settings.estimator_source);
        bytes = {};
        SceneSource source;
        source.bundle = &files;
        // Rank 0 printed the scene's warnings.
        const RenderPlan checked = check_render_settings(r.settings, r.sky);
        scene = load_session_scene(r.scene, checked.settings.materials,
                                   checked.variants.light_select->id, source, {});
        plan = plan_session_render(*scene, r, {}, source);
        files.clear();
        const std::vector<DeviceInfo> devices = select_devices(device_names, warn);
        if (devices.size() > size_t(mpi::kMaxSlots))
            throw RuntimeError("more than " + std::to_string(mpi::kMaxSlots) + " devices");
        try {
            session = std::make_unique<RenderSession>(devices, warn);
        } catch (const RuntimeError& e) {
            // The session warned of every device it skipped but the last, whose error it threw.
            if (devices.empty()) throw;
            const DeviceInfo& d = devices.back();
            throw RuntimeError("skipping device " + std::to_string(d.index) + " ('" + d.name +
                               "'): " + e.what());
        }
    } catch (const std::exception& e) {
        warn(e.what());
        session.reset();
    }

    auto serve_devices = [&](std::vector<std::unique_ptr<DeviceWorker>>& workers) {
        for (const auto& w : workers) hello.devices.emplace_back(w->report.index, w->report.name);
        mpi::send_bytes(wire::encode_hello(hello), 0, mpi::kHelloTag);
        std::vector<std::thread> threads;
        for (size_t slot = 0; slot < workers.size(); ++slot)
            threads.emplace_back([&, slot] {
                try {
                    serve_device(*workers[slot], int(slot));
                } catch (const std::exception& e) {  // a message rank 0 did not send: a bug
                    std::fprintf(stderr, "mcrt: error: rank %d: %s\n", g_rank, e.what());
                    MPI_Abort(MPI_COMM_WORLD, 1);
                }
            });
        for (std::thread& t : threads) t.join();
    };
    std::vector<std::unique_ptr<DeviceWorker>> none;
    if (session)
        session->serve(scene, plan, serve_devices, warn);
    else
        serve_devices(none);
    return int(mpi::broadcast_u64(0, 0));
}

}  // namespace mcrt
