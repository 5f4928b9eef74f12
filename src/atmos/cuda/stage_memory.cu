// atmos: device memory for the precomputation stages (render/stages.h).
#include <cuda_runtime.h>

#include <memory>

#include "cuda/device_buffer.h"
#include "render/stages.h"

namespace atmos::cuda {

namespace {
class CudaStageMemory : public StageMemory {
  public:
    float* Allocate(size_t floats) override {
        void* p = nullptr;
        Check(cudaMalloc(&p, (floats > 0 ? floats : 1) * sizeof(float)),
              "cudaMalloc (stage table)");
        return static_cast<float*>(p);
    }
    void Free(float* device) override { cudaFree(device); }
    void Upload(float* device, const float* host, size_t floats) override {
        Check(cudaMemcpy(device, host, floats * sizeof(float), cudaMemcpyHostToDevice),
              "cudaMemcpy to device (stage table)");
    }
    void Download(float* host, const float* device, size_t floats) override {
        Check(cudaMemcpy(host, device, floats * sizeof(float), cudaMemcpyDeviceToHost),
              "cudaMemcpy to host (stage table)");
    }
    void Clear(float* device, size_t floats) override {
        Check(cudaMemset(device, 0, floats * sizeof(float)), "cudaMemset (stage table)");
    }
    bool emulated() const override { return false; }
};
}  // namespace

std::unique_ptr<StageMemory> MakeCudaStageMemory() { return std::make_unique<CudaStageMemory>(); }

}  // namespace atmos::cuda
