// atmos model `bruneton`: the device code of its precomputation stages
// (models/bruneton_stages.h; render/stages.h for the mechanism).
#include "cuda/stage_launch.cuh"
#include "models/bruneton_stages.h"

ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonTransmittanceStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonDirectIrradianceStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonSingleScatteringStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonCombineStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonIncidentStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonDensityStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonIndirectIrradianceStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonAddStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonMultipleScatteringStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::BrunetonAccumulateStage)
