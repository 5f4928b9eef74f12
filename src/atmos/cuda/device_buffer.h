// atmos: device memory for the CUDA backend (nvcc / CUDA runtime only).
//
// DeviceBuffer: one cudaMalloc'd allocation, freed by its destructor (RAII,
// move-only). Tables reach the device through StageSession (render/stages.h,
// cuda/stage_memory.cu), renders included.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <utility>
#include <vector>

#include "atmos/error.h"
#include "base/texture.h"

namespace atmos::cuda {

// Throws atmos::Error naming the CUDA error and what was being done.
inline void Check(cudaError_t error, const char* what) {
    if (error != cudaSuccess) {
        Fail("CUDA: ", what, " failed: ", cudaGetErrorName(error), " (", cudaGetErrorString(error),
             ")");
    }
}

class DeviceBuffer {
  public:
    DeviceBuffer() = default;
    explicit DeviceBuffer(size_t bytes) : bytes_(bytes) {
        if (bytes > 0) Check(cudaMalloc(&data_, bytes), "cudaMalloc");
    }
    ~DeviceBuffer() {
        if (data_) cudaFree(data_);
    }
    DeviceBuffer(DeviceBuffer&& o) noexcept
        : data_(std::exchange(o.data_, nullptr)), bytes_(std::exchange(o.bytes_, 0)) {}
    DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
        if (this != &o) {
            if (data_) cudaFree(data_);
            data_ = std::exchange(o.data_, nullptr);
            bytes_ = std::exchange(o.bytes_, 0);
        }
        return *this;
    }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;

    void* data() const { return data_; }
    size_t bytes() const { return bytes_; }
    void CopyFromHost(const void* host, size_t bytes) {
        Check(cudaMemcpy(data_, host, bytes, cudaMemcpyHostToDevice), "cudaMemcpy to device");
    }
    void CopyToHost(void* host, size_t bytes) const {
        Check(cudaMemcpy(host, data_, bytes, cudaMemcpyDeviceToHost), "cudaMemcpy to host");
    }

  private:
    void* data_ = nullptr;
    size_t bytes_ = 0;
};

}  // namespace atmos::cuda
