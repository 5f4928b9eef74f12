// The precomputation stages of hillaire and atmosphere-plus on the CUDA
// backend agree with the CPU (compiled only in builds with CUDA; every test
// skips without a CUDA device).
//
// Both backends run the same stage structs (models/hillaire_stages.h,
// models/atmosphere_plus_stages.h) in double precision; the device's libm
// differs in the last ulp and nvcc may contract a*b+c into FMAs, so tables
// agree to rounding except where a discrete decision (a sun ray grazing the
// ground, a ray grazing the top) flips. Stated bound: per value
// |cuda - cpu| <= 1e-4 * max(|cpu|, 1e-6 * table max) for all but 1 value in
// 1000; a render from the device-built tables on the device against the
// CPU's: mean HDR-FLIP <= 1e-3.
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
#include "models/atmosphere_plus.h"
#include "models/hillaire.h"
#include "render/stages.h"

namespace atmos {
namespace {

constexpr double kMaxRelativeError = 1e-4;
constexpr double kFloorOfMax = 1e-6;
constexpr double kOutlierFraction = 1.0 / 1000.0;
constexpr double kMaxMeanFlip = 1e-3;

void ExpectTablesAgree(const Table& cpu, const Table& gpu, const char* what) {
    SCOPED_TRACE(what);
    ASSERT_EQ(cpu.size(), gpu.size());
    ASSERT_GT(cpu.size(), 0u);
    double peak = 0.0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        peak = std::max(peak, std::fabs(static_cast<double>(cpu.data()[i])));
    }
    size_t outliers = 0;
    double worst = 0.0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        const double a = cpu.data()[i], b = gpu.data()[i];
        ASSERT_TRUE(std::isfinite(b)) << i;
        const double rel = std::fabs(a - b) / std::max({std::fabs(a), kFloorOfMax * peak, 1e-30});
        worst = std::max(worst, rel);
        if (rel > kMaxRelativeError) ++outliers;
    }
    EXPECT_LE(static_cast<double>(outliers), kOutlierFraction * static_cast<double>(cpu.size()))
        << "worst relative error " << worst;
}

RenderRequest SmallRequest(const std::string& view, const AtmosphereParameters& atm) {
    RenderRequest r;
    r.view = GetView(view, atm);
    r.width = 64;
    r.height = 36;
    r.quantity = Quantity::kRadiance;
    r.show_progress = false;
    return r;
}

// Every stage of the log ran on `backend`, and the log holds `names` in order.
void ExpectLog(const std::vector<StageTime>& log, const std::vector<std::string>& names,
               const char* backend) {
    ASSERT_EQ(log.size(), names.size());
    for (size_t i = 0; i < log.size(); ++i) {
        EXPECT_EQ(log[i].name, names[i]);
        EXPECT_EQ(log[i].backend, backend);
        EXPECT_GE(log[i].total_ms, log[i].kernel_ms);
    }
}

HillaireModel MakeHillaire() { return HillaireModel(HillaireOptions{}); }

TEST(CudaStages, HillaireTablesMatchTheCpu) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    const AtmosphereParameters atm = EarthAtmosphere();
    HillaireModel cpu = MakeHillaire(), gpu = MakeHillaire();
    cpu.Prepare(atm);
    std::vector<StageTime> log;
    {
        const BackendScope scope(Backend::kCuda);
        const StageLogScope logging(&log);
        gpu.Prepare(atm);
    }
    ExpectLog(log, {"hillaire/transmittance", "hillaire/multiple-scattering"}, "cuda");
    ExpectTablesAgree(cpu.transmittance_table(), gpu.transmittance_table(), "transmittance");
    ExpectTablesAgree(cpu.multiple_scattering_table(), gpu.multiple_scattering_table(),
                      "multiple scattering");
    for (const char* name : {"ground-noon", "ground-sunrise", "plane-dawn"}) {
        SCOPED_TRACE(name);
        const View view = GetView(name, atm);
        const auto a = cpu.BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0, true);
        std::unique_ptr<HillaireFrame> b;
        log.clear();
        {
            const BackendScope scope(Backend::kCuda);
            const StageLogScope logging(&log);
            b = gpu.BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0, true);
        }
        ExpectLog(log, {"hillaire/sky-view", "hillaire/aerial-perspective"}, "cuda");
        ExpectTablesAgree(a->sky_view, b->sky_view, "sky-view");
        ExpectTablesAgree(a->ap_scatter, b->ap_scatter, "aerial-perspective in-scatter");
        ExpectTablesAgree(a->ap_transmittance, b->ap_transmittance,
                          "aerial-perspective transmittance");
        // The whole frame on the device (its tables and the render) against the CPU.
        const RenderRequest request = SmallRequest(name, atm);
        Image image_cpu, image_gpu;
        cpu.Render(request, &image_cpu);
        {
            const BackendScope scope(Backend::kCuda);
            gpu.Render(request, &image_gpu);
        }
        EXPECT_LE(HdrFlip(image_cpu, image_gpu).mean, kMaxMeanFlip);
    }
}

TEST(CudaStages, AtmospherePlusTablesMatchTheCpu) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    const std::map<std::string, std::string> options = {
        {"table-width", "16"}, {"table-height", "64"}, {"table-depth", "16"}, {"orders", "3"}};
    // Gather directions kept in the local array (6) and looked up per node (70).
    for (const char* theta : {"6", "70"}) {
        SCOPED_TRACE(theta);
        std::map<std::string, std::string> o = options;
        o["gather-theta"] = theta;
        std::unique_ptr<Model> cpu = CreateModel("atmosphere-plus", o);
        std::unique_ptr<Model> gpu = CreateModel("atmosphere-plus", o);
        cpu->Prepare(atm);
        std::vector<StageTime> log;
        {
            const BackendScope scope(Backend::kCuda);
            const StageLogScope logging(&log);
            gpu->Prepare(atm);
        }
        ExpectLog(log,
                  {"atmosphere-plus/transmittance", "atmosphere-plus/order-1",
                   "atmosphere-plus/gather", "atmosphere-plus/order-k", "atmosphere-plus/sum",
                   "atmosphere-plus/gather", "atmosphere-plus/order-k", "atmosphere-plus/sum"},
                  "cuda");
        const auto& a = dynamic_cast<const AtmospherePlusModel&>(*cpu).tables();
        const auto& b = dynamic_cast<const AtmospherePlusModel&>(*gpu).tables();
        ExpectTablesAgree(a.transmittance, b.transmittance, "transmittance");
        ExpectTablesAgree(a.scattering, b.scattering, "scattering");
        for (const char* name : {"ground-sunrise", "plane-noon", "orbit-dawn"}) {
            SCOPED_TRACE(name);
            const RenderRequest request = SmallRequest(name, atm);
            Image image_cpu, image_gpu;
            cpu->Render(request, &image_cpu);
            {
                const BackendScope scope(Backend::kCuda);
                gpu->Render(request, &image_gpu);
            }
            EXPECT_LE(HdrFlip(image_cpu, image_gpu).mean, kMaxMeanFlip);
        }
    }
}

}  // namespace
}  // namespace atmos
