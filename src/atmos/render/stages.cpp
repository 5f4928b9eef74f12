#include "render/stages.h"

#include <atomic>
#include <mutex>
#include <utility>

#include "atmos/error.h"

namespace atmos {

namespace {
std::atomic<std::vector<StageTime>*> g_stage_log{nullptr};
std::mutex g_stage_log_mutex;
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

}  // namespace atmos
