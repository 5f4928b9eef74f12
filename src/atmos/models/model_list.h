// atmos: THE list of models.
//
// ATMOS_MODELS(X) names every model once, as X(ModelClass, EvaluatorType):
// the model class the registry creates (models/registry.cpp: `atmos list`,
// CreateModel) and the evaluator its renders and samples launch. The same list
// feeds HasDeviceKernels (models/registry.cpp: the evaluators with device
// kernels; a device launch of any other evaluator fails with one clear error)
// and the CUDA kernels' instantiations (src/atmos/cuda/render_kernels.cu
// instantiates RenderStage and SampleStage of render/render.h for every
// EvaluatorType). The device upload is generic: the launch copies the tables
// the evaluator names in VisitTables (physics/ray.h).
//
// Adding a model: its own files, plus its header below and its X line.
// tests/emulated_device_test.cpp renders and samples every registered model on
// the emulated device (it fails for a model whose evaluator is not listed, or
// whose evaluator holds a table that VisitTables does not name).
#pragma once

#include "models/atmosphere_plus.h"
#include "models/bruneton.h"
#include "models/empty.h"
#include "models/flat.h"
#include "models/hillaire.h"
#include "models/hosek_wilkie.h"
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

// In `atmos list` order.
#define ATMOS_MODELS(X)                                                                    \
    X(EmptyModel, EmptyEvaluator)                                                          \
    X(NaiveModel, NaiveEvaluator)                                                          \
    X(ReferenceModel, ReferenceEvaluator)                                                  \
    X(OneilModel, OneilEvaluator)                                                          \
    X(SchulerModel, SchulerEvaluator)                                                      \
    X(FlatModel, FlatEvaluator)                                                            \
    X(RaymarchedModel, RaymarchedEvaluator)                                                \
    X(PreethamModel, PreethamEvaluator)                                                    \
    X(HosekWilkieModel, HosekWilkieEvaluator)                                              \
    X(TransmittanceReferenceModel, TransmittanceEvaluator<ReferenceTransmittanceOptics>)   \
    X(TransmittanceFlatModel, TransmittanceEvaluator<FlatOptics>)                          \
    X(TransmittanceErfcModel, TransmittanceEvaluator<ErfcTransmittanceOptics>)             \
    X(TransmittanceChapmanModel, TransmittanceEvaluator<ChapmanTransmittanceOptics>)       \
    X(TransmittanceOneilModel, TransmittanceEvaluator<OneilOptics>)                        \
    X(TransmittancePolynomialModel, TransmittanceEvaluator<PolynomialTransmittanceOptics>) \
    X(HillaireModel, HillaireEvaluator)                                                    \
    X(BrunetonModel, BrunetonEvaluator)                                                    \
    X(AtmospherePlusModel, AtmospherePlusEvaluator)                                        \
    X(NeuralModel, NeuralEvaluator)
