// Shared by the tests that need a CUDA device (tests/cuda_*_test.cpp, built
// only with the CUDA backend): skip, naming what cudaGetDeviceCount said,
// where there is none.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "cuda/runtime.h"

#define ATMOS_SKIP_WITHOUT_DEVICE()                                                  \
    do {                                                                             \
        std::string status;                                                          \
        if (atmos::cuda::DeviceCount(&status) <= 0) {                                \
            GTEST_SKIP() << "no CUDA device (cudaGetDeviceCount: " << status << ")"; \
        }                                                                            \
    } while (0)
