// atmos: device discovery for the CUDA backend (see cuda/runtime.h).
#include <cuda_runtime.h>

#include <string>

#include "atmos/error.h"
#include "cuda/runtime.h"

namespace atmos::cuda {

int DeviceCount(std::string* status) {
    int count = 0;
    const cudaError_t error = cudaGetDeviceCount(&count);
    if (status) {
        *status = std::string(cudaGetErrorName(error)) + " (" + cudaGetErrorString(error) + ")";
    }
    return error == cudaSuccess ? count : -1;
}

void RequireDevice() {
    std::string status;
    const int count = DeviceCount(&status);
    if (count < 0) {
        Fail("--backend cuda: no usable CUDA device: cudaGetDeviceCount returned ", status);
    }
    if (count == 0) {
        Fail("--backend cuda: no CUDA device: cudaGetDeviceCount returned ", status,
             " with 0 devices");
    }
}

}  // namespace atmos::cuda
