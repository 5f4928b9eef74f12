// atmos: the device code of model hillaire's precomputation stages
// (models/hillaire_stages.h), run by RunStage on the CUDA backend.
#include "cuda/stage_launch.cuh"
#include "models/hillaire_stages.h"

ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::HillaireTransmittanceStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::HillaireMultipleScatteringStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::HillaireSkyViewStage)
ATMOS_INSTANTIATE_DEVICE_STAGE(atmos::HillaireAerialPerspectiveStage)
