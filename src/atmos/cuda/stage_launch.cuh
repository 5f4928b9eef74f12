// atmos: the device side of RunStage (render/stages.h), nvcc only.
//
// A .cu file includes this header and the stage's header, then writes
// ATMOS_INSTANTIATE_DEVICE_STAGE(TheStage) for each stage it declared with
// ATMOS_DEVICE_STAGE.
//
// RunStageDevice copies every table the stage's VisitTables names to the
// device (one copy per distinct host pointer; outputs are copied in too, so a
// stage may accumulate into its output), launches one thread per item, times
// the kernel between CUDA events, copies the outputs back and logs the stage.
#pragma once

#include <cuda_runtime.h>

#include <chrono>
#include <cstdint>
#include <vector>

#include "cuda/device_buffer.h"
#include "render/stages.h"

namespace atmos::cuda {

template <typename Stage>
__global__ void StageKernel(Stage stage, int64_t count) {
    const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < count) stage(i);
}

// The device copies of one stage run's tables, keyed by host pointer.
class StageTables {
  public:
    // First pass: note every table and whether the stage writes it.
    void Note(const float* host, size_t floats, bool output) {
        if (!host) return;
        for (Entry& e : entries_) {
            if (e.host == host) {
                e.output = e.output || output;
                if (floats > e.floats) e.floats = floats;
                return;
            }
        }
        entries_.push_back({host, floats, output, DeviceBuffer()});
    }
    void Upload() {
        for (Entry& e : entries_) {
            e.device = DeviceBuffer(e.floats * sizeof(float));
            e.device.CopyFromHost(e.host, e.floats * sizeof(float));
        }
    }
    float* Device(const float* host) const {
        for (const Entry& e : entries_) {
            if (e.host == host) return static_cast<float*>(e.device.data());
        }
        return nullptr;
    }
    void DownloadOutputs() const {
        for (const Entry& e : entries_) {
            if (e.output) e.device.CopyToHost(const_cast<float*>(e.host), e.floats * sizeof(float));
        }
    }

  private:
    struct Entry {
        const float* host;
        size_t floats;
        bool output;
        DeviceBuffer device;
    };
    std::vector<Entry> entries_;
};

struct NoteTables {
    StageTables* tables;
    void operator()(TableView& v) const {
        tables->Note(v.data, static_cast<size_t>(v.width) * v.height * v.depth * v.channels, false);
    }
    void operator()(TableOut& o) const { tables->Note(o.data, o.size(), true); }
};

struct RepointTables {
    const StageTables* tables;
    void operator()(TableView& v) const {
        if (v.data) v.data = tables->Device(v.data);
    }
    void operator()(TableOut& o) const {
        if (o.data) o.data = tables->Device(o.data);
    }
};

template <typename Stage>
void RunStageDevice(const char* name, int64_t count, const Stage& stage) {
    const auto start = std::chrono::steady_clock::now();
    StageTables tables;
    Stage device_stage = stage;
    NoteTables note{&tables};
    device_stage.VisitTables(note);
    tables.Upload();
    RepointTables repoint{&tables};
    device_stage.VisitTables(repoint);

    constexpr unsigned kBlock = 128;
    const unsigned grid = static_cast<unsigned>((count + kBlock - 1) / kBlock);
    cudaEvent_t begin, end;
    Check(cudaEventCreate(&begin), "cudaEventCreate");
    Check(cudaEventCreate(&end), "cudaEventCreate");
    Check(cudaEventRecord(begin), "cudaEventRecord");
    StageKernel<<<grid, kBlock>>>(device_stage, count);
    Check(cudaGetLastError(), name);
    Check(cudaEventRecord(end), "cudaEventRecord");
    Check(cudaEventSynchronize(end), name);
    float kernel_ms = 0.0f;
    Check(cudaEventElapsedTime(&kernel_ms, begin, end), "cudaEventElapsedTime");
    cudaEventDestroy(begin);
    cudaEventDestroy(end);
    Check(cudaDeviceSynchronize(), name);
    tables.DownloadOutputs();
    if (CurrentStageLog()) {
        const double total_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        LogStage({name, count, "cuda", static_cast<double>(kernel_ms), total_ms});
    }
}

}  // namespace atmos::cuda

#define ATMOS_INSTANTIATE_DEVICE_STAGE(S) \
    template void atmos::cuda::RunStageDevice<S>(const char*, int64_t, const S&);
