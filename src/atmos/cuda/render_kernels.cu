// atmos: CUDA kernels over the one per-pixel function, ShadePixel().
//
// Compiled by nvcc from the same headers as the CPU build (render/render.h and
// the models' evaluators); built for the architectures of ATMOS_CUDA_ARCHITECTURES.
// RenderImageDevice / SampleAllDevice are the CUDA side of RenderImage and
// SampleAll (render/render.h), instantiated for every evaluator of
// render/device_evaluators.h.
#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

#include "cuda/device_buffer.h"
#include "cuda/device_upload.h"

#include "models/atmosphere_plus.h"
#include "models/bruneton.h"
#include "models/empty.h"
#include "models/flat.h"
#include "models/hillaire.h"
#include "models/naive.h"
#include "models/neural.h"
#include "models/oneil.h"
#include "models/preetham.h"
#include "models/raymarched.h"
#include "models/reference.h"
#include "models/schuler.h"
#include "models/transmittance_chapman.h"
#include "models/transmittance_erfc.h"
#include "models/transmittance_flat.h"
#include "models/transmittance_oneil.h"
#include "models/transmittance_polynomial.h"
#include "models/transmittance_reference.h"
#include "render/render.h"

namespace atmos {
namespace cuda {

template <typename Evaluator>
__global__ void RenderKernel(Evaluator evaluator, PixelSetup setup, ImageView out) {
    const int x = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
    const int y = static_cast<int>(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= setup.width || y >= setup.height) return;
    out.Set(x, y, ShadePixel(evaluator, setup, x, y));
}

template <typename Evaluator>
__global__ void SampleKernel(Evaluator evaluator, double bottom_radius, const SampleQuery* queries,
                             size_t count, SampleAnswer* answers) {
    const size_t i = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= count) return;
    answers[i] = SampleOne(evaluator, bottom_radius, queries[i], static_cast<uint64_t>(i));
}

template <typename Evaluator>
void RenderImageDevice(const Evaluator& evaluator, const PixelSetup& setup, ImageView out) {
    if (setup.width <= 0 || setup.height <= 0) return;
    DeviceTables tables;
    const Evaluator device_evaluator = ToDevice(evaluator, &tables);
    const size_t bytes = static_cast<size_t>(setup.width) * setup.height * 3 * sizeof(float);
    DeviceBuffer pixels(bytes);
    const ImageView view{static_cast<float*>(pixels.data()), setup.width, setup.height};
    // 16 x 8 threads (4 warps of 16 x 2 pixels): the heaviest kernels use up to
    // 166 registers per thread (ptxas, sm_90: reference 166, oneil 156, hillaire
    // and bruneton 128), so a 256-thread block fits only once per SM where
    // 128-thread blocks fit three times (12 warps instead of 8).
    const dim3 block(16, 8);
    const dim3 grid((setup.width + block.x - 1) / block.x, (setup.height + block.y - 1) / block.y);
    auto launch = [&]() {
        RenderKernel<<<grid, block>>>(device_evaluator, setup, view);
        Check(cudaGetLastError(), "render kernel launch");
    };
    DeviceTimingRequest* timing = CurrentDeviceTiming();
    if (timing && timing->repeats > 0) {
        // Kernel time only, between CUDA events (tables and pixels stay resident).
        for (int i = 0; i < timing->warmup; ++i) launch();
        cudaEvent_t start, stop;
        Check(cudaEventCreate(&start), "cudaEventCreate");
        Check(cudaEventCreate(&stop), "cudaEventCreate");
        timing->milliseconds.clear();
        for (int i = 0; i < timing->repeats; ++i) {
            Check(cudaEventRecord(start), "cudaEventRecord");
            launch();
            Check(cudaEventRecord(stop), "cudaEventRecord");
            Check(cudaEventSynchronize(stop), "cudaEventSynchronize");
            float ms = 0.0f;
            Check(cudaEventElapsedTime(&ms, start, stop), "cudaEventElapsedTime");
            timing->milliseconds.push_back(ms);
        }
        cudaEventDestroy(start);
        cudaEventDestroy(stop);
    }
    launch();
    Check(cudaDeviceSynchronize(), "render kernel");
    pixels.CopyToHost(out.data, bytes);
}

template <typename Evaluator>
void SampleAllDevice(const Evaluator& evaluator, double bottom_radius, const SampleQuery* queries,
                     size_t count, SampleAnswer* answers) {
    if (count == 0) return;
    DeviceTables tables;
    const Evaluator device_evaluator = ToDevice(evaluator, &tables);
    DeviceBuffer device_queries(count * sizeof(SampleQuery));
    device_queries.CopyFromHost(queries, count * sizeof(SampleQuery));
    DeviceBuffer device_answers(count * sizeof(SampleAnswer));
    const unsigned block = 128;
    const unsigned grid = static_cast<unsigned>((count + block - 1) / block);
    SampleKernel<<<grid, block>>>(device_evaluator, bottom_radius,
                                  static_cast<const SampleQuery*>(device_queries.data()), count,
                                  static_cast<SampleAnswer*>(device_answers.data()));
    Check(cudaGetLastError(), "sample kernel launch");
    Check(cudaDeviceSynchronize(), "sample kernel");
    device_answers.CopyToHost(answers, count * sizeof(SampleAnswer));
}

#define ATMOS_INSTANTIATE_DEVICE(E)                                             \
    template void RenderImageDevice<E>(const E&, const PixelSetup&, ImageView); \
    template void SampleAllDevice<E>(const E&, double, const SampleQuery*, size_t, SampleAnswer*);
ATMOS_DEVICE_EVALUATORS(ATMOS_INSTANTIATE_DEVICE)
#undef ATMOS_INSTANTIATE_DEVICE

}  // namespace cuda
}  // namespace atmos
