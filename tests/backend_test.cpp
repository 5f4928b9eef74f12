// The backend choice (base/parallel.h): CPU by default; `--backend cuda` fails
// with one clear error when the build has no CUDA or no device is present.
#include <gtest/gtest.h>

#include <string>

#include "atmos/error.h"
#include "base/parallel.h"
#if defined(ATMOS_HAS_CUDA)
#include "cuda/runtime.h"
#endif

namespace atmos {
namespace {

TEST(Backend, CpuIsTheDefaultAndParses) {
    EXPECT_EQ(CurrentBackend(), Backend::kCpu);
    EXPECT_EQ(ParseBackend("cpu"), Backend::kCpu);
    EXPECT_EQ(ParseBackend("cuda"), Backend::kCuda);
    EXPECT_STREQ(BackendName(Backend::kCuda), "cuda");
    EXPECT_THROW(ParseBackend("gpu"), Error);
    {
        const BackendScope scope(Backend::kCpu);
        EXPECT_EQ(CurrentBackend(), Backend::kCpu);
    }
    EXPECT_EQ(CurrentBackend(), Backend::kCpu);
}

// Without CUDA in the build, or without a device, selecting CUDA is one
// atmos::Error naming the cause, and the backend stays the CPU.
TEST(Backend, CudaIsAvailableOrFailsClearly) {
    bool device = false;
    std::string expected;
#if defined(ATMOS_HAS_CUDA)
    EXPECT_TRUE(HasCudaSupport());
    std::string status;
    device = cuda::DeviceCount(&status) > 0;
    expected = "cudaGetDeviceCount returned " + status;
#else
    EXPECT_FALSE(HasCudaSupport());
    expected = "this build has no CUDA support; configure with -DATMOS_CUDA=ON";
#endif
    if (device) {
        const BackendScope scope(Backend::kCuda);
        EXPECT_EQ(CurrentBackend(), Backend::kCuda);
    } else {
        try {
            const BackendScope scope(Backend::kCuda);
            ADD_FAILURE() << "selecting CUDA did not fail";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        }
        EXPECT_EQ(CurrentBackend(), Backend::kCpu);
    }
}

}  // namespace
}  // namespace atmos
