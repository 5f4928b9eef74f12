// atmos: the device code of model atmosphere-plus's precomputation stages
// (models/atmosphere_plus_stages.h), run by RunStage on the CUDA backend.
#include "cuda/stage_launch.cuh"
#include "models/atmosphere_plus_stages.h"

ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::AplusTransmittanceStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::AplusSingleScatteringStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::AplusGatherStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::AplusOrderStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::AplusAddStage)
