// atmos: the device side of the render and sample launches (nvcc only).
//
// RenderImage and SampleAll (render/render.h) launch RenderStage<E> and
// SampleStage<E> through RunStage, which on the CUDA backend calls
// RunStageDevice (cuda/stage_launch.cuh): the evaluator's tables (those its
// VisitTables names) are bound to device copies in the current StageSession
// (a model's resident session keeps them between renders), one thread runs
// each pixel or query, and the launch is timed in the stage log. Both stages
// are instantiated here for the evaluator of every model of
// models/model_list.h, whose headers come through that list.
#include "cuda/stage_launch.cuh"
#include "models/model_list.h"
#include "render/render.h"

namespace atmos::cuda {

#define ATMOS_INSTANTIATE_DEVICE_EVALUATOR(M, E)                                               \
    template void RunStageDevice<RenderStage<E>>(const char*, int64_t, const RenderStage<E>&); \
    template void RunStageDevice<SampleStage<E>>(const char*, int64_t, const SampleStage<E>&);
ATMOS_MODELS(ATMOS_INSTANTIATE_DEVICE_EVALUATOR)
#undef ATMOS_INSTANTIATE_DEVICE_EVALUATOR

}  // namespace atmos::cuda
