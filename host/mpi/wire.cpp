#include "mpi/wire.h"

#include <cstring>

#include "common/error.h"

namespace mcrt::wire {
namespace {

// The first word of every message says what it is; kInputs also marks the format's version.
enum : uint64_t {
    kInputs = 0x6d637274696e7031,  // "mcrtinp1"
    kHello = 2,
    kItem = 3,
    kStop = 4,
    kResult = 5,
    kFailure = 6
};

class Writer {
  public:
    void u64(uint64_t v) { raw(&v, sizeof v); }
    void f64(double v) { raw(&v, sizeof v); }
    void str(const std::string& s) {
        u64(s.size());
        raw(s.data(), s.size());
    }
    void raw(const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        bytes.insert(bytes.end(), p, p + n);
    }
    Bytes bytes;
};

// Reads what Writer wrote; a message cut short or of the wrong kind is a RuntimeError (a rank
// of another build, or memory gone bad), never a read past the end.
class Reader {
  public:
    explicit Reader(const Bytes& b) : p_(b.data()), end_(b.data() + b.size()) {}
    uint64_t u64() {
        uint64_t v;
        raw(&v, sizeof v);
        return v;
    }
    double f64() {
        double v;
        raw(&v, sizeof v);
        return v;
    }
    std::string str() {
        uint64_t n = u64();
        check(n);
        std::string s(reinterpret_cast<const char*>(p_), n);
        p_ += n;
        return s;
    }
    void raw(void* out, size_t n) {
        check(n);
        if (n) std::memcpy(out, p_, n);
        p_ += n;
    }
    void expect(uint64_t kind, const char* what) {
        if (u64() != kind) throw RuntimeError(std::string("MPI: a message that is not ") + what);
    }
    void done() const {
        if (p_ != end_) throw RuntimeError("MPI: a message longer than its content");
    }

  private:
    void check(uint64_t n) const {
        if (n > uint64_t(end_ - p_)) throw RuntimeError("MPI: a message cut short");
    }
    const unsigned char* p_;
    const unsigned char* end_;
};

void write_item(Writer& w, const WorkItem& item) {
    w.u64(item.seq);
    w.u64(item.chunk_begin);
    w.u64(item.chunk_end);
    w.u64(uint64_t(item.pixel_begin) << 32 | item.pixel_end);
}

WorkItem read_item(Reader& r) {
    WorkItem item;
    item.seq = r.u64();
    item.chunk_begin = uint32_t(r.u64());
    item.chunk_end = uint32_t(r.u64());
    uint64_t pixels = r.u64();
    item.pixel_begin = uint32_t(pixels >> 32);
    item.pixel_end = uint32_t(pixels);
    return item;
}

}  // namespace

Bytes encode_inputs(const FileBundle& files, const std::string& estimator_source) {
    Writer w;
    w.u64(kInputs);
    w.u64(files.size());
    for (const auto& [path, data] : files) {
        w.str(path);
        w.u64(data.size());
        w.raw(data.data(), data.size());
    }
    w.str(estimator_source);
    return std::move(w.bytes);
}

void decode_inputs(const Bytes& bytes, FileBundle& files, std::string& estimator_source) {
    Reader r(bytes);
    r.expect(kInputs, "the render's inputs");
    files.clear();
    const uint64_t count = r.u64();
    for (uint64_t k = 0; k < count; ++k) {
        std::string path = r.str();
        const uint64_t size = r.u64();
        if (size > bytes.size()) throw RuntimeError("MPI: a message cut short");
        std::vector<unsigned char>& data = files[path];
        data.resize(size);
        r.raw(data.data(), size);
    }
    estimator_source = r.str();
    r.done();
}

Bytes encode_hello(const Hello& hello) {
    Writer w;
    w.u64(kHello);
    w.str(hello.host);
    w.u64(hello.devices.size());
    for (const auto& [index, name] : hello.devices) {
        w.u64(uint64_t(int64_t(index)));
        w.str(name);
    }
    w.u64(hello.warnings.size());
    for (const std::string& warning : hello.warnings) w.str(warning);
    return std::move(w.bytes);
}

Hello decode_hello(const Bytes& bytes) {
    Reader r(bytes);
    r.expect(kHello, "a rank's hello");
    Hello hello;
    hello.host = r.str();
    const uint64_t devices = r.u64();
    for (uint64_t k = 0; k < devices && k < bytes.size(); ++k) {
        int index = int(int64_t(r.u64()));
        hello.devices.emplace_back(index, r.str());
    }
    const uint64_t warnings = r.u64();
    for (uint64_t k = 0; k < warnings && k < bytes.size(); ++k) hello.warnings.push_back(r.str());
    r.done();
    return hello;
}

Bytes encode_item(const std::optional<WorkItem>& item) {
    Writer w;
    w.u64(item ? kItem : kStop);
    write_item(w, item.value_or(WorkItem{}));
    return std::move(w.bytes);
}

std::optional<WorkItem> decode_item(const Bytes& bytes) {
    Reader r(bytes);
    const uint64_t kind = r.u64();
    if (kind != kItem && kind != kStop)
        throw RuntimeError("MPI: a message that is not a work item");
    WorkItem item = read_item(r);
    r.done();
    if (kind == kStop) return std::nullopt;
    return item;
}

Bytes encode_result(const ResultMessage& m) {
    Writer w;
    if (m.failed) {
        w.u64(kFailure);
        w.str(m.error);
        return std::move(w.bytes);
    }
    w.u64(kResult);
    write_item(w, m.result.item);
    w.u64(m.target_samples);
    w.u64(m.samples);
    w.f64(m.seconds_busy);
    w.f64(m.seconds_run);
    // The item's runs (pixel × chunk × replicate), as the device wrote them.
    w.u64(m.result.sums.size());
    w.raw(m.result.sums.data(), m.result.sums.size() * sizeof(gpu::ChunkSums));
    return std::move(w.bytes);
}

ResultMessage decode_result(const Bytes& bytes, const WorkItem& item) {
    Reader r(bytes);
    ResultMessage m;
    const uint64_t kind = r.u64();
    if (kind == kFailure) {
        m.failed = true;
        m.error = r.str();
        r.done();
        return m;
    }
    if (kind != kResult) throw RuntimeError("MPI: a message that is not a work item's result");
    const WorkItem got = read_item(r);
    if (got.seq != item.seq || got.chunk_begin != item.chunk_begin ||
        got.chunk_end != item.chunk_end || got.pixel_begin != item.pixel_begin ||
        got.pixel_end != item.pixel_end)
        throw RuntimeError("MPI: the result of another work item than the one sent");
    m.target_samples = r.u64();
    m.samples = r.u64();
    m.seconds_busy = r.f64();
    m.seconds_run = r.f64();
    m.result.item = item;
    const uint64_t runs = r.u64();
    const uint64_t per_replicate = uint64_t(item.pixel_count()) * item.chunk_count();
    if (runs == 0 || per_replicate == 0 || runs % per_replicate != 0 ||
        runs > bytes.size() / sizeof(gpu::ChunkSums))
        throw RuntimeError("MPI: a result whose sums do not fit its work item");
    m.result.sums.resize(size_t(runs));
    r.raw(m.result.sums.data(), size_t(runs) * sizeof(gpu::ChunkSums));
    r.done();
    return m;
}

}  // namespace mcrt::wire
