// Issue 18: nothing silently wrong (the ground at altitude 0, non-finite
// values, fuzzed queries).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "physics/ray.h"
#include "render/render.h"

namespace {

using namespace atmos;

// The output guard's count is an error in tests (issue 18 item 3): every test
// that made the guard replace a value is named, and the run fails.
class GuardListener : public ::testing::EmptyTestEventListener {
  public:
    void OnTestStart(const ::testing::TestInfo&) override { start_ = OutputGuardCount(); }
    void OnTestEnd(const ::testing::TestInfo& info) override {
        const int64_t n = OutputGuardCount() - start_;
        if (n > 0) {
            std::fprintf(stderr, "output guard: %s.%s replaced %lld value(s)\n",
                         info.test_suite_name(), info.name(), static_cast<long long>(n));
            offenders_.push_back(std::string(info.test_suite_name()) + "." + info.name());
        }
    }
    static std::vector<std::string> offenders_;

  private:
    int64_t start_ = 0;
};
std::vector<std::string> GuardListener::offenders_;

class GuardEnvironment : public ::testing::Environment {
  public:
    void TearDown() override {
        for (const std::string& name : GuardListener::offenders_) {
            ADD_FAILURE() << name << ": the output guard replaced NaN/Inf/negative values";
        }
    }
};

const bool kGuardInstalled = [] {
    ::testing::UnitTest::GetInstance()->listeners().Append(new GuardListener);
    ::testing::AddGlobalTestEnvironment(new GuardEnvironment);
    return true;
}();

// Issue 18 item 2: a camera at altitude 0 looking down sees the lit ground, as
// a camera 0.5 m above it does (there the ray meets the ground about a metre
// away, so both see the same ground through practically no air). Before the
// fix every model but bruneton gave 0 at altitude 0.
TEST(Reliability, GroundBelowACameraAtAltitudeZeroIsLit) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.3);
    const Vec3d up(0.0, 0.0, 1.0);
    const Vec3d forward = Normalize(Vec3d(1.0, 0.0, -1.7));  // 60 degrees down
    const Vec3d sun = Normalize(Vec3d(-0.5, 0.3, 0.8));
    for (const ModelInfo& info : ListModels()) {
        // reference: fixed by its own change (issue 18, path tracer); preetham,
        // hosek-wilkie and the transmittance models produce no ground at all.
        // neural: its shipped weights were fitted at albedo 0 and refuse this
        // atmosphere (issue 15, Neural.WeightsCheckCoversEveryFieldTheFitDependsOn);
        // its evaluator calls the same GroundAtCamera as the others.
        if (info.name == "reference" || info.name == "preetham" || info.name == "hosek-wilkie" ||
            info.name == "neural" || !info.capabilities.radiance) {
            continue;
        }
        SCOPED_TRACE(info.name);
        // Small tables for the precomputed models (the defaults take a minute).
        std::map<std::string, std::string> options;
        if (info.name == "bruneton") {
            options = {{"scattering-r", "8"},        {"scattering-mu", "32"},
                       {"scattering-mu-s", "8"},     {"scattering-nu", "4"},
                       {"scattering-samples", "10"}, {"orders", "2"}};
        } else if (info.name == "atmosphere-plus") {
            options = {{"table-width", "8"},
                       {"table-height", "16"},
                       {"table-depth", "8"},
                       {"orders", "2"}};
        }
        std::unique_ptr<Model> model = CreateModel(info.name, options);
        model->Prepare(atm);
        Image images[2];
        const double altitudes[2] = {0.0, 0.5};
        for (int k = 0; k < 2; ++k) {
            RenderRequest request;
            request.view.camera =
                MakeCamera(Vec3d(0.0, 0.0, atm.bottom_radius + altitudes[k]), forward, up, 20.0);
            request.view.sun_direction = sun;
            request.view.sun_irradiance = 1.0;
            request.width = 8;
            request.height = 6;
            request.show_progress = false;
            model->Render(request, &images[k]);
        }
        // The direct-sun Lambert term alone: albedo / pi * mu_s * T_sun <= 0.3 / pi.
        const double lambert_max = 0.3 / kPi * Dot(sun, up);
        for (int y = 0; y < 6; ++y) {
            for (int x = 0; x < 8; ++x) {
                const Rgb at0 = images[0].Get(x, y);
                const Rgb above = images[1].Get(x, y);
                for (int c = 0; c < 3; ++c) {
                    EXPECT_GT(above[c], 0.1 * lambert_max) << x << "," << y;
                    EXPECT_NEAR(at0[c], above[c], 0.02f * above[c]) << x << "," << y << " c" << c;
                }
            }
        }
    }
}

// An evaluator that answers NaN, infinity and a negative value.
struct BrokenEvaluator {
    static constexpr bool kHostOnly = true;
    ATMOS_HD RayResult Evaluate(const Vec3d&, const Vec3d& dir, const Vec3d&, bool) const {
        RayResult r;
        r.sky = Rgb(std::nanf(""), dir.x > 0.0 ? INFINITY : 1.0f, -1.0f);
        r.transmittance = Rgb(1.0f);
        return r;
    }
};

// The guard replaces and counts what it catches, in renders and samples.
TEST(Reliability, OutputGuardCountsWhatItReplaces) {
    ASSERT_TRUE(kGuardInstalled);
    const int64_t before = OutputGuardCount();
    AtmosphereParameters atm = EarthAtmosphere();
    RenderRequest request;
    request.view = GetView("ground-noon", atm);
    request.width = 4;
    request.height = 2;
    const PixelSetup setup = MakePixelSetup(request, atm);
    Image image(4, 2);
    RenderImage(BrokenEvaluator{}, setup, image.View(), false);
    int64_t expected = 0;
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 4; ++x) {
            const Rgb c = image.Get(x, y);
            EXPECT_EQ(c.x, 0.0f);
            EXPECT_EQ(c.z, 0.0f);
            expected += 2 + (c.y == 0.0f ? 1 : 0);
        }
    }
    EXPECT_EQ(OutputGuardCount() - before, expected);
    const std::vector<SampleAnswer> a =
        SampleAll(BrokenEvaluator{}, atm.bottom_radius, {SampleQuery{}, SampleQuery{}});
    EXPECT_EQ(a[0].radiance.x, 0.0f);
    EXPECT_EQ(OutputGuardCount() - before, expected + 4);  // NaN and -1 per query
    ResetOutputGuardCount(before);                         // deliberate: not a defect of this run
}

// Issue 18 item 3: a layer without its exponential term is no term at all
// (0 x exp(h) was 0 x inf = NaN above ~700 m: a black image).
TEST(Reliability, ZeroExpTermLayerIsNoTerm) {
    AtmosphereParameters atm = EarthAtmosphere();
    AtmosphereParameters odd = atm;
    odd.absorption_density.layers[1].exp_term = 0.0;
    odd.absorption_density.layers[1].exp_scale = 1.0;  // exp(h) overflows above 709 m
    ValidateAtmosphere(odd);
    const int64_t before = OutputGuardCount();
    for (const char* name : {"naive", "schuler", "hillaire", "atmosphere-plus"}) {
        SCOPED_TRACE(name);
        const std::map<std::string, std::string> small =
            std::string(name) == "atmosphere-plus"
                ? std::map<std::string, std::string>{{"table-width", "8"},
                                                     {"table-height", "16"},
                                                     {"table-depth", "8"},
                                                     {"orders", "2"}}
                : std::map<std::string, std::string>{};
        std::unique_ptr<Model> a = CreateModel(name, small), b = CreateModel(name, small);
        a->Prepare(atm);
        b->Prepare(odd);
        const std::vector<SampleQuery> q = {{1000.0, 0.3, 0.5, 0.0}, {20e3, -0.2, 0.2, 90.0}};
        const std::vector<SampleAnswer> x = a->Sample(q), y = b->Sample(q);
        for (size_t i = 0; i < q.size(); ++i) {
            for (int c = 0; c < 3; ++c) {
                EXPECT_GT(x[i].radiance[c], 0.0f);
                EXPECT_FLOAT_EQ(y[i].radiance[c], x[i].radiance[c]);
            }
        }
    }
    EXPECT_EQ(OutputGuardCount(), before);
}

// Issue 18 item 3: a solar irradiance whose radiance overflows is rejected,
// naming the field and the range (1e308 gave infinity, written as black).
TEST(Reliability, HugeSolarIrradianceIsRejected) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.solar_irradiance = Vec3d(1.0, 1e308, 1.0);
    try {
        ValidateAtmosphere(atm);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("solar_irradiance"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("1e+09"), std::string::npos) << e.what();
    }
}

// Issue 18 item 3: on a giant planet (bottom radius 1e9 m, the atmosphere 5e8 m
// thick, 8 km scale height) naive's zenith transmittance converges with its
// steps to the plane-parallel closed form exp(-sum beta_i H_i) (the planet is
// flat at that scale), and its default 16 steps are as close as on Earth; it
// was 1 at any step count (uniform steps over 5e8 m all fell where there is
// no air).
TEST(Reliability, NaiveFollowsTheDensityOnAGiantPlanet) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.absorption_extinction = Vec3d(0.0);
    atm.bottom_radius = 1e9;
    atm.top_radius = 1.5e9;
    ValidateAtmosphere(atm);
    for (const char* steps : {"16", "256"}) {
        SCOPED_TRACE(steps);
        std::unique_ptr<Model> model = CreateModel("naive", {{"steps", steps}});
        model->Prepare(atm);
        const std::vector<SampleAnswer> a = model->Sample({{0.0, 1.0, 0.8, 0.0}});
        const double tolerance = std::string(steps) == "16" ? 0.03 : 0.003;
        for (int c = 0; c < 3; ++c) {
            const double tau = atm.rayleigh_scattering[c] * 8000.0 + atm.mie_extinction[c] * 1200.0;
            EXPECT_NEAR(a[0].transmittance[c], std::exp(-tau), tolerance * std::exp(-tau)) << c;
            EXPECT_GT(a[0].radiance[c], 1e-4f) << c;
        }
    }
}

}  // namespace
