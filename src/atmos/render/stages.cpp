#include "render/stages.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <utility>

#include "atmos/error.h"

namespace atmos {

#if defined(ATMOS_HAS_CUDA)
namespace cuda {
std::unique_ptr<StageMemory> MakeCudaStageMemory();  // src/atmos/cuda/stage_memory.cu
}  // namespace cuda
#endif

namespace {
std::atomic<std::vector<StageTime>*> g_stage_log{nullptr};
std::mutex g_stage_log_mutex;
std::atomic<StageSession*> g_session{nullptr};

// Host memory standing in for the device (Backend::kEmulatedDevice).
class EmulatedStageMemory : public StageMemory {
  public:
    float* Allocate(size_t floats) override { return new float[floats > 0 ? floats : 1]; }
    void Free(float* device) override { delete[] device; }
    void Upload(float* device, const float* host, size_t floats) override {
        std::memcpy(device, host, floats * sizeof(float));
    }
    void Download(float* host, const float* device, size_t floats) override {
        std::memcpy(host, device, floats * sizeof(float));
    }
    void Clear(float* device, size_t floats) override { Poison(device, floats); }
    bool emulated() const override { return true; }
    static void Poison(float* p, size_t floats) {
        for (size_t i = 0; i < floats; ++i) p[i] = std::numeric_limits<float>::quiet_NaN();
    }
};

// Bitwise equality (NaN == NaN).
bool SameBits(const float* a, const float* b, size_t floats) {
    return std::memcmp(a, b, floats * sizeof(float)) == 0;
}
}  // namespace

StageLogScope::StageLogScope(std::vector<StageTime>* log) : previous_(g_stage_log.exchange(log)) {}
StageLogScope::~StageLogScope() { g_stage_log.store(previous_); }
std::vector<StageTime>* CurrentStageLog() { return g_stage_log.load(); }

void LogStage(StageTime entry) {
    const std::lock_guard<std::mutex> lock(g_stage_log_mutex);
    if (std::vector<StageTime>* log = g_stage_log.load()) log->push_back(std::move(entry));
}

void FailNoDeviceStage(const char* name, bool has_cuda) {
    if (!has_cuda) {
        Fail("--backend cuda: this build has no CUDA support; configure with -DATMOS_CUDA=ON");
    }
    Fail("--backend cuda: precomputation stage '", name,
         "' has no device code (declare it with ATMOS_DEVICE_STAGE and instantiate it in a .cu "
         "file)");
}

std::unique_ptr<StageMemory> MakeStageMemory(Backend backend) {
    if (backend == Backend::kEmulatedDevice) return std::make_unique<EmulatedStageMemory>();
#if defined(ATMOS_HAS_CUDA)
    if (backend == Backend::kCuda) return cuda::MakeCudaStageMemory();
#endif
    Fail("precomputation stages: no device memory on the ", BackendName(backend), " backend");
}

StageSession* CurrentStageSession() { return g_session.load(); }

StageSession::StageSession() {
    const Backend backend = CurrentBackend();
    StageSession* current = g_session.load();
    if (current && current->active() && current->backend() == backend) {
        parent_ = current;
        while (parent_->parent_) parent_ = parent_->parent_;
        return;
    }
    backend_ = backend;
    if (IsDeviceBackend(backend)) memory_ = MakeStageMemory(backend);
    previous_ = g_session.exchange(this);
}

StageSession::StageSession(Detached) : detached_(true) {
    backend_ = CurrentBackend();
    if (IsDeviceBackend(backend_)) memory_ = MakeStageMemory(backend_);
}

StageSession* StageSession::Enter(StageSession* session) { return g_session.exchange(session); }
void StageSession::Leave(StageSession* previous) { g_session.store(previous); }

bool StageSession::emulated() const {
    const StageSession* r = root();
    return r->memory_ && r->memory_->emulated();
}

StageSession::~StageSession() {
    if (parent_) return;
    if (!detached_) g_session.store(previous_);
    if (memory_) {
        for (Entry& e : entries_) memory_->Free(e.device);
        LogDownloads();
    }
}

StageSession::Entry* StageSession::Find(const float* host, uint64_t id) {
    for (Entry& e : entries_) {
        if (id != 0 ? e.id == id : (e.id == 0 && e.host == host)) return &e;
    }
    return nullptr;
}

void StageSession::Download(Table* table) {
    if (parent_) return parent_->Download(table);
    if (!memory_ || !table->size()) return;
    Entry* e = Find(table->data(), table->id());
    if (!e || !e->device_newer) return;
    memory_->Download(table->data(), e->device, e->floats);
    downloaded_bytes_ += static_cast<int64_t>(e->floats * sizeof(float));
    session_downloads_ += static_cast<int64_t>(e->floats * sizeof(float));
    e->device_newer = false;
}

void StageSession::HostWrote(const Table& table) {
    if (parent_) return parent_->HostWrote(table);
    if (!memory_) return;
    Entry* e = Find(table.data(), table.id());
    if (!e) return;
    if (e->device_newer) {
        Fail(
            "precomputation: the host wrote a table whose device copy is newer (Download it "
            "first)");
    }
    memory_->Upload(e->device, table.data(), e->floats);
    uploaded_bytes_ += static_cast<int64_t>(e->floats * sizeof(float));
}

void StageSession::Acquire(const char* stage, const std::vector<StageTableRef>& refs,
                           std::vector<float*>* device) {
    if (parent_) return parent_->Acquire(stage, refs, device);
    device->clear();
    for (const StageTableRef& r : refs) {
        Entry* e = Find(r.host, r.id);
        if (e && e->floats != r.floats) {
            Fail("precomputation stage '", stage, "': a table changed size under the same id");
        }
        if (!e) {
            // A table with new storage at the address of an older one: the old
            // one is gone (resized or destroyed), and so is its device copy.
            for (size_t i = 0; i < entries_.size(); ++i) {
                if (entries_[i].host == r.host) {
                    memory_->Free(entries_[i].device);
                    entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(i));
                    break;
                }
            }
            entries_.push_back({r.host, r.floats, r.id, memory_->Allocate(r.floats), false});
            e = &entries_.back();
            if (r.output && !r.accumulate) {
                memory_->Clear(e->device, e->floats);
            } else {
                memory_->Upload(e->device, r.host, r.floats);
                uploaded_bytes_ += static_cast<int64_t>(r.floats * sizeof(float));
            }
        } else if (memory_->emulated() && !e->device_newer &&
                   !SameBits(r.host, e->device, e->floats)) {
            Fail("precomputation stage '", stage,
                 "': a table changed on the host after its device copy was made (call "
                 "StageSession::HostWrote)");
        }
        device->push_back(e->device);
    }
}

void StageSession::Produced(const std::vector<StageTableRef>& refs) {
    if (parent_) return parent_->Produced(refs);
    for (const StageTableRef& r : refs) {
        if (!r.output) continue;
        Entry* e = Find(r.host, r.id);
        if (!e || e->device_newer) continue;
        e->device_newer = true;
        if (memory_->emulated()) {
            EmulatedStageMemory::Poison(const_cast<float*>(r.host), r.floats);
        }
    }
}

void StageSession::DownloadOutputs(const std::vector<StageTableRef>& refs) {
    if (parent_) return parent_->DownloadOutputs(refs);
    for (const StageTableRef& r : refs) {
        if (!r.output) continue;
        Entry* e = Find(r.host, r.id);
        if (!e || !e->device_newer) continue;
        memory_->Download(const_cast<float*>(r.host), e->device, e->floats);
        downloaded_bytes_ += static_cast<int64_t>(r.floats * sizeof(float));
        e->device_newer = false;
    }
}

void StageSession::LogDownloads() {
    if (parent_) return parent_->LogDownloads();
    if (!memory_ || session_downloads_ == 0) return;
    if (CurrentStageLog()) {
        StageTime t;
        t.name = "downloads";
        t.backend = memory_->emulated() ? "emulated-device" : "cuda";
        t.bytes_down = session_downloads_;
        LogStage(t);
    }
    session_downloads_ = 0;
}

void StageSession::ForgetViews(const std::vector<StageTableRef>& refs) {
    if (parent_) return parent_->ForgetViews(refs);
    for (const StageTableRef& r : refs) {
        if (r.id != 0) continue;
        for (size_t i = 0; i < entries_.size(); ++i) {
            if (entries_[i].id == 0 && entries_[i].host == r.host) {
                memory_->Free(entries_[i].device);
                entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(i));
                break;
            }
        }
    }
}

void StageSession::KeepOnly(const std::vector<uint64_t>& ids) {
    if (parent_) return parent_->KeepOnly(ids);
    std::vector<Entry> kept;
    for (Entry& e : entries_) {
        if (e.id != 0 && std::find(ids.begin(), ids.end(), e.id) != ids.end()) {
            kept.push_back(e);
        } else {
            memory_->Free(e.device);
        }
    }
    entries_ = std::move(kept);
}

// A TableView at an 8-byte aligned offset looks like: a non-null pointer, a
// shape of 1..2^24 texels per axis with 1..4 channels, and the id of a Table
// of this process.
void StageSession::CheckNamedTables(const char* stage, const unsigned char* bytes, size_t size,
                                    const std::vector<size_t>& named) const {
    const uint64_t last_id = Table::LastId();
    for (size_t off = 0; off + sizeof(TableView) <= size; off += alignof(TableView)) {
        bool overlaps_named = false;
        for (size_t i = 0; i + 1 < named.size(); i += 2) {
            overlaps_named = overlaps_named ||
                             (off + sizeof(TableView) > named[i] && off < named[i] + named[i + 1]);
        }
        if (overlaps_named) continue;
        TableView v;
        std::memcpy(&v, bytes + off, sizeof v);
        const int kMax = 1 << 24;
        if (v.data && v.id >= 1 && v.id <= last_id && v.width >= 1 && v.width <= kMax &&
            v.height >= 1 && v.height <= kMax && v.depth >= 1 && v.depth <= kMax &&
            v.channels >= 1 && v.channels <= 4) {
            Fail("device launch '", stage, "': the stage holds a table (id ", v.id, ", ", v.width,
                 " x ", v.height, " x ", v.depth, " x ", v.channels, ", at byte ", off,
                 ") that its VisitTables does not name: the device would read it through a host "
                 "pointer");
        }
    }
}

ResidentScope::ResidentScope(ResidentTables* tables) {
    const Backend backend = CurrentBackend();
    if (!IsDeviceBackend(backend)) return;
    if (!tables->session_ || tables->session_->backend() != backend) {
        tables->session_ = std::make_unique<StageSession>(StageSession::Detached{});
    }
    session_ = tables->session_.get();
    previous_ = StageSession::Enter(session_);
}

ResidentScope::~ResidentScope() {
    if (!session_) return;
    StageSession::Leave(previous_);
    session_->KeepOnly(keep_);
    session_->LogDownloads();
}

}  // namespace atmos
