// atmos: THE loop of the project (RunStage): the precomputations (the tables
// of bruneton, hillaire, atmosphere-plus), the renders and the samples
// (render/render.h: RenderStage, SampleStage), on the CPU or, in a CUDA build,
// on the device, from the same source, all timed in one log.
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
// Joining and resident sessions. A StageSession made while another is current
// (on the same device backend) joins it: its calls go to the current one and
// it frees nothing. A model keeps its tables on the device from Prepare() to
// its renders with a ResidentTables member: a ResidentScope makes the model's
// own session current for a Prepare, Render or Sample (the precomputation's
// sessions join it), and on exit keeps only the device copies of the tables
// its evaluator names (Keep), so a second render uploads nothing.
//
// Transient stages (`static constexpr bool kTransient = true`: the render and
// sample launches) have their outputs copied back after the run, and their
// id-0 views (memory that is not a Table: the image, the queries) dropped
// from the session.
//
// On the emulated device, every stage copy is also checked, after its tables
// are re-pointed, for a TableView its VisitTables does not name (a table the
// device would read through a host pointer): one clear error.
//
// A StageLogScope collects, per stage run (every RunStage: precomputation
// stages, "render" and "sample"), the name, item count, backend, the time
// (wall time on the CPU; on the device, the kernel alone between CUDA events
// and the whole call with the copies) and the bytes copied: the one timing log
// of the project (`atmos bench` prints it and writes its stages CSV from it).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "base/parallel.h"
#include "base/progress.h"
#include "base/texture.h"
#include "physics/ray.h"

#include "base/non_copyable.h"

namespace atmos {

// True for stages with device code (ATMOS_DEVICE_STAGE).
template <typename Stage>
struct HasDeviceStage : std::false_type {};

// True for stages that declare kTransient (see the top of this file).
template <typename S, typename = void>
struct IsTransientStage : std::false_type {};
template <typename S>
struct IsTransientStage<S, std::void_t<decltype(S::kTransient)>>
    : std::integral_constant<bool, S::kTransient> {};

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
class StageLogScope : private NonCopyable {
  public:
    explicit StageLogScope(std::vector<StageTime>* log);
    ~StageLogScope();

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
class StageSession : private NonCopyable {
  public:
    StageSession();   // joins the current session, or opens one (current while alive)
    ~StageSession();  // frees the device copies; copies nothing back
    // A session that is not made current (ResidentTables): ResidentScope
    // makes it current.
    struct Detached {};
    explicit StageSession(Detached);

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
    // Drops the device copies of `refs` whose id is 0 (transient launches).
    void ForgetViews(const std::vector<StageTableRef>& refs);
    // Drops every device copy but those of tables with an id in `ids`.
    void KeepOnly(const std::vector<uint64_t>& ids);
    // Fails when `stage_bytes` (a stage copy whose named tables were
    // re-pointed) still holds a host TableView that is not one of the named
    // ones (`named_offsets`: pairs of offset and size; emulated device only,
    // see the top of this file).
    void CheckNamedTables(const char* stage, const unsigned char* stage_bytes, size_t size,
                          const std::vector<size_t>& named_offsets) const;
    bool active() const { return root()->memory_ != nullptr; }
    bool emulated() const;
    Backend backend() const { return root()->backend_; }
    int64_t uploaded_bytes() const { return root()->uploaded_bytes_; }
    int64_t downloaded_bytes() const { return root()->downloaded_bytes_; }
    // Logs the bytes of the Download() calls since the last such entry as one
    // "downloads" entry (when there were any, and a log is installed).
    void LogDownloads();
    // Makes `session` current; returns the one it replaces (for Leave).
    static StageSession* Enter(StageSession* session);
    static void Leave(StageSession* previous);

  private:
    struct Entry {
        const float* host;
        size_t floats;
        uint64_t id;
        float* device;
        bool device_newer;
    };
    Entry* Find(const float* host, uint64_t id);
    const StageSession* root() const { return parent_ ? parent_ : this; }
    StageSession* parent_ = nullptr;  // the session this one joined
    bool detached_ = false;
    Backend backend_ = Backend::kCpu;
    int64_t session_downloads_ = 0;  // bytes of Download() calls (logged at the end)
    std::unique_ptr<StageMemory> memory_;
    std::vector<Entry> entries_;
    StageSession* previous_ = nullptr;
    int64_t uploaded_bytes_ = 0, downloaded_bytes_ = 0;
};
StageSession* CurrentStageSession();

// A model's device copies, kept from Prepare() to its renders (see the top of
// this file). Reset() drops them all.
class ResidentTables {
  public:
    void Reset() { session_.reset(); }
    StageSession* session() const { return session_.get(); }

  private:
    friend class ResidentScope;
    std::unique_ptr<StageSession> session_;
};

// Makes a model's resident session current while alive (on a device backend;
// inert on the CPU). On exit, only the tables named by Keep() stay on the
// device.
class ResidentScope : private NonCopyable {
  public:
    explicit ResidentScope(ResidentTables* tables);
    ~ResidentScope();
    // Keeps the device copies of the tables `evaluator` names (VisitTables).
    template <typename Evaluator>
    void Keep(const Evaluator& evaluator);

  private:
    StageSession* session_ = nullptr;
    StageSession* previous_ = nullptr;
    std::vector<uint64_t> keep_;
};

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
// The byte offsets, inside a stage, of the tables its VisitTables names.
struct NamedTableOffsets {
    const unsigned char* base;
    std::vector<size_t>* offsets;
    // Pairs (offset, size).
    void operator()(TableView& v) const {
        offsets->push_back(static_cast<size_t>(reinterpret_cast<unsigned char*>(&v) - base));
        offsets->push_back(sizeof(TableView));
    }
    void operator()(TableOut& o) const {
        offsets->push_back(static_cast<size_t>(reinterpret_cast<unsigned char*>(&o) - base));
        offsets->push_back(sizeof(TableOut));
    }
};
// The ids of the Tables a stage or evaluator names.
struct CollectTableIds {
    std::vector<uint64_t>* ids;
    void operator()(TableView& v) const {
        if (v.id) ids->push_back(v.id);
    }
    void operator()(TableOut& o) const {
        if (o.id) ids->push_back(o.id);
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
        if (session_->emulated()) {
            std::vector<size_t> named;
            NamedTableOffsets offsets{reinterpret_cast<const unsigned char*>(&stage_), &named};
            stage_.VisitTables(offsets);
            session_->CheckNamedTables(name, reinterpret_cast<const unsigned char*>(&stage_),
                                       sizeof(Stage), named);
        }
    }
    const Stage& stage() const { return stage_; }
    void Finish() {
        session_->Produced(refs_);
        if (own_ || IsTransientStage<Stage>::value) session_->DownloadOutputs(refs_);
        if (IsTransientStage<Stage>::value) session_->ForgetViews(refs_);
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

template <typename Evaluator>
void ResidentScope::Keep(const Evaluator& evaluator) {
    Evaluator copy = evaluator;
    CollectTableIds collect{&keep_};
    VisitEvaluatorTables(copy, collect);
}

// Calls body(i) for i in [0, count) in chunks of `grain`, advancing `progress`
// (may be null) once per chunk.
template <typename Body>
void ParallelForWithProgress(int64_t count, int64_t grain, Progress* progress, const Body& body) {
    if (!progress) {
        ParallelFor(count, grain, [&](int64_t i) { body(i); });
        return;
    }
    const int64_t chunks = (count + grain - 1) / grain;
    ParallelFor(chunks, 1, [&](int64_t c) {
        const int64_t end = c * grain + grain < count ? c * grain + grain : count;
        for (int64_t i = c * grain; i < end; ++i) body(i);
        progress->Add(end - c * grain);
    });
}

// Runs stage(i) for i in [0, count) on the current backend (see the top of
// this file); `progress` (may be null) is advanced by one per item.
// Runs body(i) for i < count on the CPU (ParallelFor), whatever the backend,
// and logs it as a CPU stage: the stages of the wide channel batches, which
// have no device form.
template <typename Body>
void RunCpuStage(const char* name, int64_t count, int64_t grain, const Body& body) {
    const auto start = std::chrono::steady_clock::now();
    ParallelFor(count, grain, body);
    if (CurrentStageLog()) {
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        LogStage({name, count, "cpu", ms, ms});
    }
}

template <typename Stage>
void RunStage(const char* name, int64_t count, int64_t grain, const Stage& stage,
              Progress* progress = nullptr) {
    static_assert(std::is_trivially_copyable<Stage>::value,
                  "stages are passed to kernels by value");
    if (count <= 0) return;
    const Backend backend = CurrentBackend();
    if (backend == Backend::kCuda) {
#if defined(ATMOS_HAS_CUDA)
        if constexpr (HasDeviceStage<Stage>::value) {
            cuda::RunStageDevice(name, count, stage);
            if (progress) progress->Add(count);
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
        ParallelForWithProgress(count, grain, progress, [&](int64_t i) { copy(i); });
        binding.Finish();
        up = binding.bytes_up();
        down = binding.bytes_down();
    } else {
        ParallelForWithProgress(count, grain, progress, [&](int64_t i) { stage(i); });
    }
    if (CurrentStageLog()) {
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        LogStage({name, count, BackendName(backend), ms, ms, up, down});
    }
}

}  // namespace atmos
