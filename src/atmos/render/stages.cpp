#include "render/stages.h"

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
    if (IsDeviceBackend(backend)) memory_ = MakeStageMemory(backend);
    previous_ = g_session.exchange(this);
}

StageSession::~StageSession() {
    g_session.store(previous_);
    if (memory_) {
        for (Entry& e : entries_) memory_->Free(e.device);
        if (CurrentStageLog() && session_downloads_ > 0) {
            StageTime t;
            t.name = "downloads";
            t.backend = memory_->emulated() ? "emulated-device" : "cuda";
            t.bytes_down = session_downloads_;
            LogStage(t);
        }
    }
}

StageSession::Entry* StageSession::Find(const float* host, uint64_t id) {
    for (Entry& e : entries_) {
        if (id != 0 ? e.id == id : (e.id == 0 && e.host == host)) return &e;
    }
    return nullptr;
}

void StageSession::Download(Table* table) {
    if (!memory_ || !table->size()) return;
    Entry* e = Find(table->data(), table->id());
    if (!e || !e->device_newer) return;
    memory_->Download(table->data(), e->device, e->floats);
    downloaded_bytes_ += static_cast<int64_t>(e->floats * sizeof(float));
    session_downloads_ += static_cast<int64_t>(e->floats * sizeof(float));
    e->device_newer = false;
}

void StageSession::HostWrote(const Table& table) {
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
    for (const StageTableRef& r : refs) {
        if (!r.output) continue;
        Entry* e = Find(r.host, r.id);
        if (!e || !e->device_newer) continue;
        memory_->Download(const_cast<float*>(r.host), e->device, e->floats);
        downloaded_bytes_ += static_cast<int64_t>(r.floats * sizeof(float));
        e->device_newer = false;
    }
}

}  // namespace atmos
