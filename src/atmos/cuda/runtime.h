// atmos: the host-side face of the CUDA runtime (no CUDA headers here, so the
// CPU sources can include it). Defined in src/atmos/cuda/runtime.cu; only
// built and called when ATMOS_HAS_CUDA is defined.
#pragma once

#include <string>

namespace atmos::cuda {

// Number of CUDA devices, or -1 when cudaGetDeviceCount failed; `status`
// receives cudaGetDeviceCount's error name and description.
int DeviceCount(std::string* status);

// Throws one clear atmos::Error unless a CUDA device can be used, naming what
// cudaGetDeviceCount returned.
void RequireDevice();

}  // namespace atmos::cuda
