// atmos: THE loop of the precomputations (the tables of bruneton, hillaire,
// atmosphere-plus), on the CPU or, in a CUDA build, on the device, from the
// same source.
//
// A stage is a trivially copyable struct:
//
//   struct MyStage {
//       TableView input;    // tables it reads (host pointers)
//       TableOut output;    // tables it writes (host pointers)
//       template <typename V> void VisitTables(V& v) { v(input); v(output); }
//       ATMOS_HD void operator()(int64_t item) const;  // does item `item`
//   };
//
// Items must be independent (each writes its own texels), so the result does not
// depend on the schedule. An output is written whole (every texel, none read)
// unless it was made with Table::out(true) (`accumulate`: the stage reads it
// too). RunStage(name, count, grain, stage) calls stage(i) for i in [0, count):
// - CPU backend: through the project's one ParallelFor (chunks of `grain`);
// - CUDA backend: for stages declared with ATMOS_DEVICE_STAGE (below) and
//   instantiated in a .cu file with ATMOS_INSTANTIATE_DEVICE_STAGE
//   (src/atmos/cuda/stage_launch.cuh): every table VisitTables names gets a
//   device copy (inputs and accumulated outputs uploaded, whole outputs only
//   allocated), one thread runs each item;
// - emulated-device backend (tests): the CUDA backend's bookkeeping with host
//   memory standing in for the device, the items run by ParallelFor on the
//   copies (see below).
//
// Device copies and StageSession. Without a session, a device run copies its
// tables to the device, runs, and copies its outputs back. Inside a
// StageSession (one per precomputation), device copies stay on the device
// between stages, keyed by Table::id(): an input the device already holds is not
// uploaded again, and outputs are NOT copied back; the driver calls
// session.Download(&table) for each table the host needs (the final tables,
// and any it reads between stages), and session.HostWrote(table) after writing
// a table on the host that the device holds. A Table whose storage is replaced
// (Resize, assignment) gets a new id, so a stale copy is never used.
//
// The emulated-device backend checks that discipline: after a stage, the host
// copy of each output is filled with NaN until Download() restores it (a host
// read without Download sees NaN); before a stage, a host copy that changed
// without HostWrote() is one clear error; whole outputs start as NaN (a stage
// that reads one, or leaves texels unwritten, produces NaN); and a table a stage
// reads but does not name keeps its host pointer, which the emulation cannot
// catch (tests poison the host tables themselves for that, e.g.
// tests/bruneton_stages_test.cpp).
//
// A StageLogScope collects, per stage run, the name, item count and the time:
// wall time on the CPU; on the device, the kernel alone between CUDA events
// and the whole call with the copies (`atmos bench` prints them).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "base/parallel.h"
#include "base/texture.h"

namespace atmos {

// True for stages with device code (ATMOS_DEVICE_STAGE).
template <typename Stage>
struct HasDeviceStage : std::false_type {};

// Declares, next to a stage's definition (at namespace atmos scope), that a .cu
// file instantiates it with ATMOS_INSTANTIATE_DEVICE_STAGE. A stage declared
// but not instantiated fails to link in a CUDA build.
#define ATMOS_DEVICE_STAGE(S) \
    template <>               \
    struct HasDeviceStage<S> : std::true_type {};

struct StageTime {
    std::string name;
    int64_t items = 0;
    std::string backend;     // "cpu", "cuda" or "emulated-device"
    double kernel_ms = 0.0;  // CPU: the ParallelFor; CUDA: between events around the kernel
    double total_ms = 0.0;   // CUDA: with the copies to and from the device
    // Device backends: bytes copied to / from the device by this run (a
    // session's later Download() calls are logged as one "downloads" entry
    // when the session ends).
    int64_t bytes_up = 0, bytes_down = 0;
};

// Installs a log that every RunStage appends to while it lives (process-wide;
// nested scopes: the innermost wins).
class StageLogScope {
  public:
    explicit StageLogScope(std::vector<StageTime>* log);
    ~StageLogScope();
    StageLogScope(const StageLogScope&) = delete;
    StageLogScope& operator=(const StageLogScope&) = delete;

  private:
    std::vector<StageTime>* previous_;
};
std::vector<StageTime>* CurrentStageLog();
void LogStage(StageTime entry);

[[noreturn]] void FailNoDeviceStage(const char* name, bool has_cuda);

// Where device copies live: CUDA memory, or host memory for the emulation.
class StageMemory {
  public:
    virtual ~StageMemory() = default;
    virtual float* Allocate(size_t floats) = 0;
    virtual void Free(float* device) = 0;
    virtual void Upload(float* device, const float* host, size_t floats) = 0;
    virtual void Download(float* host, const float* device, size_t floats) = 0;
    // Fills a new whole-output copy (CUDA: zeros; emulation: NaN).
    virtual void Clear(float* device, size_t floats) = 0;
    virtual bool emulated() const = 0;
};
// The memory of the current backend (CUDA or emulated); throws on the CPU.
std::unique_ptr<StageMemory> MakeStageMemory(Backend backend);

// One table a stage names (collected by VisitTables).
struct StageTableRef {
    const float* host = nullptr;
    size_t floats = 0;
    uint64_t id = 0;
    bool output = false;
    bool accumulate = false;
};

// The device copies of one precomputation (see the top of this file). Inert on
// the CPU backend. Process-wide while alive (the innermost is current).
class StageSession {
  public:
    StageSession();
    ~StageSession();  // frees the device copies; copies nothing back
    StageSession(const StageSession&) = delete;
    StageSession& operator=(const StageSession&) = delete;

    // Makes the host copy of `table` current (no-op when it is, or on the CPU).
    void Download(Table* table);
    // The host wrote `table`: the device copy, if any, is stale.
    void HostWrote(const Table& table);

    // Used by RunStage: device pointers current for the stage's tables (uploads
    // what is needed), then, after the run, marks the outputs as newer on the
    // device (emulation: poisons their host copies).
    void Acquire(const char* stage, const std::vector<StageTableRef>& refs,
                 std::vector<float*>* device);
    void Produced(const std::vector<StageTableRef>& refs);
    // Copies every output of `refs` back (a run outside any session).
    void DownloadOutputs(const std::vector<StageTableRef>& refs);
    bool active() const { return memory_ != nullptr; }
    int64_t uploaded_bytes() const { return uploaded_bytes_; }
    int64_t downloaded_bytes() const { return downloaded_bytes_; }

  private:
    struct Entry {
        const float* host;
        size_t floats;
        uint64_t id;
        float* device;
        bool device_newer;
    };
    Entry* Find(const float* host, uint64_t id);
    int64_t session_downloads_ = 0;  // bytes of Download() calls (logged at the end)
    std::unique_ptr<StageMemory> memory_;
    std::vector<Entry> entries_;
    StageSession* previous_ = nullptr;
    int64_t uploaded_bytes_ = 0, downloaded_bytes_ = 0;
};
StageSession* CurrentStageSession();

// Collects the tables a stage names; then re-points them to device copies.
struct CollectStageTables {
    std::vector<StageTableRef>* refs;
    void operator()(TableView& v) const {
        if (v.data) {
            refs->push_back({v.data, static_cast<size_t>(v.width) * v.height * v.depth * v.channels,
                             v.id, false, false});
        }
    }
    void operator()(TableOut& o) const {
        if (o.data) refs->push_back({o.data, o.size(), o.id, true, o.accumulate});
    }
};
struct RepointStageTables {
    const std::vector<float*>* device;
    size_t next = 0;
    void operator()(TableView& v) {
        if (v.data) v.data = (*device)[next++];
    }
    void operator()(TableOut& o) {
        if (o.data) o.data = (*device)[next++];
    }
};

// The device side of one stage run: binds the stage's tables to device copies
// in the current session (or a session of its own, which copies the outputs
// back in Finish()).
template <typename Stage>
class StageBinding {
  public:
    StageBinding(const char* name, const Stage& stage) : stage_(stage) {
        session_ = CurrentStageSession();
        if (!session_ || !session_->active()) {
            own_ = std::make_unique<StageSession>();
            session_ = own_.get();
        }
        up0_ = session_->uploaded_bytes();
        down0_ = session_->downloaded_bytes();
        CollectStageTables collect{&refs_};
        stage_.VisitTables(collect);
        session_->Acquire(name, refs_, &device_);
        RepointStageTables repoint{&device_};
        stage_.VisitTables(repoint);
    }
    const Stage& stage() const { return stage_; }
    void Finish() {
        session_->Produced(refs_);
        if (own_) session_->DownloadOutputs(refs_);
    }
    // Bytes this run copied (uploads in the constructor, downloads in Finish).
    int64_t bytes_up() const { return session_->uploaded_bytes() - up0_; }
    int64_t bytes_down() const { return session_->downloaded_bytes() - down0_; }

  private:
    Stage stage_;
    std::vector<StageTableRef> refs_;
    std::vector<float*> device_;
    StageSession* session_ = nullptr;
    std::unique_ptr<StageSession> own_;
    int64_t up0_ = 0, down0_ = 0;
};

#if defined(ATMOS_HAS_CUDA)
namespace cuda {
// Defined in src/atmos/cuda/stage_launch.cuh; instantiated per stage.
template <typename Stage>
void RunStageDevice(const char* name, int64_t count, const Stage& stage);
}  // namespace cuda
#endif

template <typename Stage>
void RunStage(const char* name, int64_t count, int64_t grain, const Stage& stage) {
    static_assert(std::is_trivially_copyable<Stage>::value,
                  "stages are passed to kernels by value");
    if (count <= 0) return;
    const Backend backend = CurrentBackend();
    if (backend == Backend::kCuda) {
#if defined(ATMOS_HAS_CUDA)
        if constexpr (HasDeviceStage<Stage>::value) {
            cuda::RunStageDevice(name, count, stage);
            return;
        } else {
            FailNoDeviceStage(name, true);
        }
#else
        FailNoDeviceStage(name, false);
#endif
    }
    const auto start = std::chrono::steady_clock::now();
    int64_t up = 0, down = 0;
    if (backend == Backend::kEmulatedDevice) {
        StageBinding<Stage> binding(name, stage);
        const Stage& copy = binding.stage();
        ParallelFor(count, grain, [&](int64_t i) { copy(i); });
        binding.Finish();
        up = binding.bytes_up();
        down = binding.bytes_down();
    } else {
        ParallelFor(count, grain, [&](int64_t i) { stage(i); });
    }
    if (CurrentStageLog()) {
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        LogStage({name, count, BackendName(backend), ms, ms, up, down});
    }
}

}  // namespace atmos
