// Model `bruneton`: the precomputation on the CUDA backend (every stage of
// models/bruneton_stages.h on the device) against the CPU backend. Compiled
// only in builds with CUDA; every test skips without a CUDA device.
//
// Stated bounds: every table texel and channel |cuda - cpu| <= 1e-4 *
// max(|cpu|, 1e-6 * table max) (double precision on both; the device contracts
// FMAs and its libm differs in the last ulp; all lookups are continuous, so
// rounding does not flip a texel), and the mean HDR-FLIP of a render from the
// device's tables (on the device) against one from the CPU's (on the CPU) is
// <= 1e-3.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cuda/runtime.h"
#include "cuda_test_util.h"
#include "metrics/flip.h"
#include "models/bruneton.h"
#include "render/stages.h"

namespace atmos {
namespace {

constexpr double kMaxRelative = 1e-4;
constexpr double kMaxMeanFlip = 1e-3;

// Sizes small enough for the CPU side to stay fast; 4 orders, ground albedo.
std::map<std::string, std::string> SmallOptions(const char* mie_storage) {
    return {{"scattering-r", "16"}, {"scattering-mu", "64"}, {"scattering-mu-s", "16"},
            {"scattering-nu", "8"}, {"orders", "4"},         {"mie-storage", mie_storage}};
}

BrunetonConfig Options(const char* mie_storage) {
    return BrunetonModel::OptionRows().Parse("bruneton", SmallOptions(mie_storage));
}

void ExpectTablesAgree(const Table& cpu, const Table& gpu, const char* what) {
    ASSERT_EQ(cpu.size(), gpu.size()) << what;
    double peak = 0.0;
    for (size_t i = 0; i < cpu.size(); ++i) peak = std::max(peak, std::fabs(double{cpu.data()[i]}));
    double worst = 0.0;
    size_t bad = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        const double a = cpu.data()[i], b = gpu.data()[i];
        const double rel = std::fabs(a - b) / std::max({std::fabs(a), 1e-6 * peak, 1e-30});
        worst = std::max(worst, rel);
        if (!(rel <= kMaxRelative)) ++bad;
    }
    EXPECT_EQ(bad, 0u) << what << ": worst relative difference " << worst;
}

TEST(CudaBrunetonStages, DeviceTablesMatchTheCpu) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.3, 0.3, 0.3);
    for (const char* storage : {"separate", "combined"}) {
        SCOPED_TRACE(storage);
        BrunetonModel cpu_model(Options(storage));
        BrunetonModel gpu_model(Options(storage));
        {
            const BackendScope scope(Backend::kCpu);
            cpu_model.Prepare(atm);
        }
        std::vector<StageTime> log;
        {
            const BackendScope scope(Backend::kCuda);
            const StageLogScope log_scope(&log);
            gpu_model.Prepare(atm);
        }
        ASSERT_FALSE(log.empty());
        for (const StageTime& s : log) EXPECT_EQ(s.backend, "cuda") << s.name;
        const BrunetonTables& a = cpu_model.tables();
        const BrunetonTables& b = gpu_model.tables();
        ExpectTablesAgree(a.transmittance, b.transmittance, "transmittance");
        ExpectTablesAgree(a.irradiance, b.irradiance, "irradiance");
        ExpectTablesAgree(a.scattering, b.scattering, "scattering");
        ExpectTablesAgree(a.single_mie, b.single_mie, "single mie");
    }
}

TEST(CudaBrunetonStages, RenderFromDeviceTablesMatchesTheCpu) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    const AtmosphereParameters atm = EarthAtmosphere();
    std::unique_ptr<Model> cpu_model = CreateModel("bruneton", SmallOptions("separate"));
    std::unique_ptr<Model> gpu_model = CreateModel("bruneton", SmallOptions("separate"));
    {
        const BackendScope scope(Backend::kCpu);
        cpu_model->Prepare(atm);
    }
    {
        const BackendScope scope(Backend::kCuda);
        gpu_model->Prepare(atm);
    }
    for (const char* view : {"ground-noon", "ground-sunrise", "orbit-noon"}) {
        SCOPED_TRACE(view);
        RenderRequest request;
        request.view = GetView(view, atm);
        request.width = 96;
        request.height = 54;
        request.quantity = Quantity::kRadiance;
        request.show_progress = false;
        Image cpu, gpu;
        {
            const BackendScope scope(Backend::kCpu);
            cpu_model->Render(request, &cpu);
        }
        {
            const BackendScope scope(Backend::kCuda);
            gpu_model->Render(request, &gpu);
        }
        ASSERT_EQ(cpu.size(), gpu.size());
        EXPECT_LE(HdrFlip(cpu, gpu).mean, kMaxMeanFlip);
    }
}

}  // namespace
}  // namespace atmos
