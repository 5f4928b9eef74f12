// CPU and CUDA backends agree (compiled only in builds with CUDA; every test
// skips without a CUDA device).
//
// Deterministic models: the same ShadePixel() runs on both; the device may
// contract a*b+c into FMAs and its libm differs in the last ulp, so images
// agree to rounding except where a discrete decision (shadow edge, horizon)
// flips. Stated bound, per model, at 64 x 36 on four views: per pixel
// |cuda - cpu| <= 1e-3 * max(|cpu|, 1e-3 * image max) for all but 1 pixel in
// 500, and mean HDR-FLIP(cpu, cuda) <= 1e-3. `sample` answers: relative 1e-3.
//
// The path tracer: same estimator (and the same keyed random streams, though
// rounding can make paths diverge), so the image means (per channel) must agree
// within 4 sigma of their batch-means standard errors.
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

namespace atmos {
namespace {

constexpr double kMaxRelativeError = 1e-3;
constexpr double kOutlierFraction = 1.0 / 500.0;
constexpr double kMaxMeanFlip = 1e-3;

Image RenderOn(Backend backend, const Model& model, const RenderRequest& request) {
    const BackendScope scope(backend);
    Image image;
    model.Render(request, &image);
    return image;
}

RenderRequest SmallRequest(const std::string& view, const AtmosphereParameters& atm,
                           Quantity quantity) {
    RenderRequest r;
    r.view = GetView(view, atm);
    r.width = 64;
    r.height = 36;
    r.quantity = quantity;
    r.show_progress = false;
    return r;
}

TEST(CudaParity, EveryDeterministicModelMatchesTheCpu) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    const AtmosphereParameters atm = EarthAtmosphere();
    for (const ModelInfo& info : ListModels()) {
        if (info.capabilities.stochastic) continue;
        SCOPED_TRACE(info.name);
        std::unique_ptr<Model> model = CreateModel(info.name);
        model->Prepare(atm);
        const Quantity quantity =
            info.capabilities.radiance ? Quantity::kRadiance : Quantity::kTransmittance;
        for (const char* view : {"ground-noon", "ground-sunrise", "plane-dawn", "orbit-noon"}) {
            SCOPED_TRACE(view);
            const RenderRequest request = SmallRequest(view, atm, quantity);
            const Image cpu = RenderOn(Backend::kCpu, *model, request);
            const Image gpu = RenderOn(Backend::kCuda, *model, request);
            ASSERT_EQ(cpu.size(), gpu.size());
            float peak = 0.0f;
            for (size_t i = 0; i < cpu.size(); ++i) peak = std::max(peak, cpu.data()[i]);
            const double floor = 1e-3 * static_cast<double>(peak);
            size_t outliers = 0;
            double worst = 0.0;
            for (size_t i = 0; i < cpu.size(); ++i) {
                const double a = cpu.data()[i], b = gpu.data()[i];
                const double rel = std::fabs(a - b) / std::max({std::fabs(a), floor, 1e-30});
                worst = std::max(worst, rel);
                if (rel > kMaxRelativeError) ++outliers;
            }
            EXPECT_LE(static_cast<double>(outliers),
                      kOutlierFraction * static_cast<double>(cpu.size()))
                << "worst relative error " << worst;
            if (quantity == Quantity::kRadiance) {
                EXPECT_LE(HdrFlip(cpu, gpu).mean, kMaxMeanFlip);
            }
        }
    }
}

TEST(CudaParity, SampleMatchesTheCpu) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    const AtmosphereParameters atm = EarthAtmosphere();
    std::vector<SampleQuery> queries;
    for (double alt : {0.0, 5e3, 30e3}) {
        for (double mu : {-0.3, 0.02, 0.5, 1.0}) {
            for (double mu_s : {-0.05, 0.1, 0.8}) queries.push_back({alt, mu, mu_s, 60.0});
        }
    }
    for (const ModelInfo& info : ListModels()) {
        if (info.capabilities.stochastic) continue;
        SCOPED_TRACE(info.name);
        std::unique_ptr<Model> model = CreateModel(info.name);
        model->Prepare(atm);
        std::vector<SampleAnswer> cpu, gpu;
        {
            const BackendScope scope(Backend::kCpu);
            cpu = model->Sample(queries);
        }
        {
            const BackendScope scope(Backend::kCuda);
            gpu = model->Sample(queries);
        }
        ASSERT_EQ(cpu.size(), gpu.size());
        for (size_t i = 0; i < cpu.size(); ++i) {
            for (int c = 0; c < 3; ++c) {
                const double a = cpu[i].radiance[c], b = gpu[i].radiance[c];
                EXPECT_LE(std::fabs(a - b), kMaxRelativeError * std::max(std::fabs(a), 1e-6))
                    << "query " << i;
                const double ta = cpu[i].transmittance[c], tb = gpu[i].transmittance[c];
                EXPECT_LE(std::fabs(ta - tb), kMaxRelativeError * std::max(std::fabs(ta), 1e-6))
                    << "query " << i;
            }
        }
    }
}

TEST(CudaParity, PathTracerAgreesStatistically) {
    ATMOS_SKIP_WITHOUT_DEVICE();
    const AtmosphereParameters atm = EarthAtmosphere();
    std::unique_ptr<Model> model = CreateModel("reference");
    model->Prepare(atm);
    RenderRequest request = SmallRequest("ground-sunrise", atm, Quantity::kRadiance);
    request.monte_carlo.spp = 64;
    request.monte_carlo.pass_spp = 8;
    request.width = 32;
    request.height = 18;
    Image cpu_var, gpu_var;
    request.variance = &cpu_var;
    const Image cpu = RenderOn(Backend::kCpu, *model, request);
    request.variance = &gpu_var;
    const Image gpu = RenderOn(Backend::kCuda, *model, request);
    const size_t pixels = static_cast<size_t>(request.width) * request.height;
    for (int c = 0; c < 3; ++c) {
        double mean_cpu = 0.0, mean_gpu = 0.0, var = 0.0;
        for (size_t p = 0; p < pixels; ++p) {
            mean_cpu += static_cast<double>(cpu.data()[3 * p + c]);
            mean_gpu += static_cast<double>(gpu.data()[3 * p + c]);
            var += static_cast<double>(cpu_var.data()[3 * p + c]) +
                   static_cast<double>(gpu_var.data()[3 * p + c]);
        }
        const double n = static_cast<double>(pixels);
        // Pixels are independent estimates: Var(image mean) = sum Var(pixel) / n^2.
        const double sigma = std::sqrt(var) / n;
        EXPECT_LE(std::fabs(mean_cpu - mean_gpu) / n, 4.0 * sigma + 1e-7 * mean_cpu / n)
            << "channel " << c;
    }
}

}  // namespace
}  // namespace atmos
