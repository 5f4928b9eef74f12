// atmos: THE list of evaluators with CUDA kernels.
//
// ATMOS_DEVICE_EVALUATORS(X) names every evaluator type that
// src/atmos/cuda/render_kernels.cu instantiates its render and sample kernels
// for; HasDeviceKernels<E> is true for exactly those (the types are only
// forward-declared here). RenderImage / SampleAll on the CUDA backend call the
// kernels for these and fail with one clear error for any other evaluator.
// Add a new model's evaluator here (and, if it holds tables, give it a
// ToDevice() overload in src/atmos/cuda/device_upload.h).
#pragma once

#include <type_traits>

namespace atmos {

struct EmptyEvaluator;
struct ReferenceEvaluator;
struct NaiveEvaluator;
struct HillaireEvaluator;
struct FlatEvaluator;
struct RaymarchedEvaluator;
struct SchulerEvaluator;
struct OneilEvaluator;
struct PreethamEvaluator;
struct BrunetonEvaluator;
struct AtmospherePlusEvaluator;
struct NeuralEvaluator;
template <typename Optics>
struct TransmittanceEvaluator;
struct ReferenceTransmittanceOptics;
struct FlatOptics;
struct ErfcTransmittanceOptics;
struct ChapmanTransmittanceOptics;
struct OneilOptics;
struct PolynomialTransmittanceOptics;

#define ATMOS_DEVICE_EVALUATORS(X)                          \
    X(EmptyEvaluator)                                       \
    X(ReferenceEvaluator)                                   \
    X(NaiveEvaluator)                                       \
    X(HillaireEvaluator)                                    \
    X(FlatEvaluator)                                        \
    X(RaymarchedEvaluator)                                  \
    X(SchulerEvaluator)                                     \
    X(OneilEvaluator)                                       \
    X(PreethamEvaluator)                                    \
    X(BrunetonEvaluator)                                    \
    X(AtmospherePlusEvaluator)                              \
    X(NeuralEvaluator)                                      \
    X(TransmittanceEvaluator<ReferenceTransmittanceOptics>) \
    X(TransmittanceEvaluator<FlatOptics>)                   \
    X(TransmittanceEvaluator<ErfcTransmittanceOptics>)      \
    X(TransmittanceEvaluator<ChapmanTransmittanceOptics>)   \
    X(TransmittanceEvaluator<OneilOptics>)                  \
    X(TransmittanceEvaluator<PolynomialTransmittanceOptics>)

template <typename E>
struct HasDeviceKernels : std::false_type {};
#define ATMOS_DEVICE_TRAIT(E) \
    template <>               \
    struct HasDeviceKernels<E> : std::true_type {};
ATMOS_DEVICE_EVALUATORS(ATMOS_DEVICE_TRAIT)
#undef ATMOS_DEVICE_TRAIT

}  // namespace atmos
