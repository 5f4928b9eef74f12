// atmos: the device side of RunStage (render/stages.h), nvcc only.
//
// A .cu file includes this header and the stage's header, then writes
// ATMOS_INSTANTIATE_DEVICE_STAGE(TheStage) for each stage it declared with
// ATMOS_DEVICE_STAGE; render_kernels.cu instantiates the render and sample
// launches (RenderStage, SampleStage of render/render.h) for every model of
// models/model_list.h.
//
// RunStageDevice binds the stage's tables to device copies (StageBinding: in
// the current StageSession, or copied in and out around this one run),
// launches one thread per item, times the kernel between CUDA events and logs
// the stage.
#pragma once

#include <cuda_runtime.h>

#include <chrono>
#include <cstdint>

#include "cuda/device_buffer.h"
#include "render/stages.h"

namespace atmos::cuda {

template <typename Stage>
__global__ void StageKernel(Stage stage, int64_t count) {
    const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < count) stage(i);
}

template <typename Stage>
void RunStageDevice(const char* name, int64_t count, const Stage& stage) {
    const auto start = std::chrono::steady_clock::now();
    StageBinding<Stage> binding(name, stage);
    constexpr unsigned kBlock = 128;
    const unsigned grid = static_cast<unsigned>((count + kBlock - 1) / kBlock);
    cudaEvent_t begin, end;
    Check(cudaEventCreate(&begin), "cudaEventCreate");
    Check(cudaEventCreate(&end), "cudaEventCreate");
    Check(cudaEventRecord(begin), "cudaEventRecord");
    StageKernel<<<grid, kBlock>>>(binding.stage(), count);
    Check(cudaGetLastError(), name);
    Check(cudaEventRecord(end), "cudaEventRecord");
    Check(cudaEventSynchronize(end), name);
    float kernel_ms = 0.0f;
    Check(cudaEventElapsedTime(&kernel_ms, begin, end), "cudaEventElapsedTime");
    cudaEventDestroy(begin);
    cudaEventDestroy(end);
    Check(cudaDeviceSynchronize(), name);
    binding.Finish();
    if (CurrentStageLog()) {
        const double total_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        LogStage({name, count, "cuda", static_cast<double>(kernel_ms), total_ms, binding.bytes_up(),
                  binding.bytes_down()});
    }
}

}  // namespace atmos::cuda

#define ATMOS_INSTANTIATE_DEVICE_STAGE(S) \
    template void atmos::cuda::RunStageDevice<S>(const char*, int64_t, const S&);
