// atmos: CUDA kernels over the one per-pixel function, ShadePixel().
//
// Compiled by nvcc from the same headers as the CPU build (render/render.h and
// the models' evaluators); built for the architectures of ATMOS_CUDA_ARCHITECTURES.
#include <cuda_runtime.h>

#include "models/bruneton.h"
#include "models/atmosphere_plus.h"
#include "models/empty.h"
#include "models/flat.h"
#include "models/hillaire.h"
#include "models/naive.h"
#include "models/neural.h"
#include "models/reference.h"
#include "models/oneil.h"
#include "models/preetham.h"
#include "models/raymarched.h"
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

// Renders into device memory `device_pixels` (width * height * 3 floats).
// Returns the CUDA error of the launch.
template <typename Evaluator>
cudaError_t LaunchRender(const Evaluator& evaluator, const PixelSetup& setup, float* device_pixels,
                         cudaStream_t stream) {
    const dim3 block(16, 16);
    const dim3 grid((setup.width + block.x - 1) / block.x, (setup.height + block.y - 1) / block.y);
    ImageView view{device_pixels, setup.width, setup.height};
    RenderKernel<<<grid, block, 0, stream>>>(evaluator, setup, view);
    return cudaGetLastError();
}

template cudaError_t LaunchRender<EmptyEvaluator>(const EmptyEvaluator&, const PixelSetup&, float*,
                                                  cudaStream_t);
template cudaError_t LaunchRender<ReferenceEvaluator>(const ReferenceEvaluator&, const PixelSetup&,
                                                      float*, cudaStream_t);
template cudaError_t LaunchRender<NaiveEvaluator>(const NaiveEvaluator&, const PixelSetup&, float*,
                                                  cudaStream_t);
template cudaError_t LaunchRender<HillaireEvaluator>(const HillaireEvaluator&, const PixelSetup&,
                                                     float*, cudaStream_t);

template cudaError_t LaunchRender<FlatEvaluator>(const FlatEvaluator&, const PixelSetup&, float*,
                                                 cudaStream_t);
template cudaError_t LaunchRender<RaymarchedEvaluator>(const RaymarchedEvaluator&,
                                                       const PixelSetup&, float*, cudaStream_t);
template cudaError_t LaunchRender<SchulerEvaluator>(const SchulerEvaluator&, const PixelSetup&,
                                                    float*, cudaStream_t);
template cudaError_t LaunchRender<OneilEvaluator>(const OneilEvaluator&, const PixelSetup&, float*,
                                                  cudaStream_t);
template cudaError_t LaunchRender<PreethamEvaluator>(const PreethamEvaluator&, const PixelSetup&,
                                                     float*, cudaStream_t);
template cudaError_t LaunchRender<TransmittanceEvaluator<ReferenceTransmittanceOptics>>(
    const TransmittanceEvaluator<ReferenceTransmittanceOptics>&, const PixelSetup&, float*,
    cudaStream_t);
template cudaError_t LaunchRender<TransmittanceEvaluator<FlatOptics>>(
    const TransmittanceEvaluator<FlatOptics>&, const PixelSetup&, float*, cudaStream_t);
template cudaError_t LaunchRender<TransmittanceEvaluator<ErfcTransmittanceOptics>>(
    const TransmittanceEvaluator<ErfcTransmittanceOptics>&, const PixelSetup&, float*,
    cudaStream_t);
template cudaError_t LaunchRender<TransmittanceEvaluator<ChapmanTransmittanceOptics>>(
    const TransmittanceEvaluator<ChapmanTransmittanceOptics>&, const PixelSetup&, float*,
    cudaStream_t);
template cudaError_t LaunchRender<TransmittanceEvaluator<OneilOptics>>(
    const TransmittanceEvaluator<OneilOptics>&, const PixelSetup&, float*, cudaStream_t);
template cudaError_t LaunchRender<TransmittanceEvaluator<PolynomialTransmittanceOptics>>(
    const TransmittanceEvaluator<PolynomialTransmittanceOptics>&, const PixelSetup&, float*,
    cudaStream_t);
template cudaError_t LaunchRender<BrunetonEvaluator>(const BrunetonEvaluator&, const PixelSetup&,
                                                     float*, cudaStream_t);
template cudaError_t LaunchRender<AtmospherePlusEvaluator>(const AtmospherePlusEvaluator&,
                                                           const PixelSetup&, float*, cudaStream_t);
template cudaError_t LaunchRender<NeuralEvaluator>(const NeuralEvaluator&, const PixelSetup&,
                                                   float*, cudaStream_t);

}  // namespace cuda
}  // namespace atmos
