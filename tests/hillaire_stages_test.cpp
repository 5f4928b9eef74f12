// Model hillaire's precomputation stages (models/hillaire_stages.h): the CPU
// path runs the stage structs themselves through RunStage (the tables' content
// is tested in hillaire_test.cpp), so these tests check the wiring: which
// stages Prepare, a render's frame and Sample run, over how many items, and
// that the stages are device stages.
#include <gtest/gtest.h>

#include <string>
#include <type_traits>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "models/hillaire.h"
#include "models/hillaire_stages.h"
#include "render/stages.h"
#include "test_util.h"

namespace atmos {
namespace {

static_assert(
    atmos_test::kAreDeviceStages<HillaireTransmittanceStage, HillaireMultipleScatteringStage,
                                 HillaireSkyViewStage, HillaireAerialPerspectiveStage>,
    "device stages");

HillaireModel MakeModel() { return HillaireModel(HillaireOptions{}); }

std::vector<std::string> Names(const std::vector<StageTime>& log) {
    std::vector<std::string> names;
    for (const StageTime& t : log) names.push_back(t.name);
    return names;
}

TEST(HillaireStages, PrepareRenderAndSampleRunTheirTablesAsStages) {
    const AtmosphereParameters atm = EarthAtmosphere();
    HillaireModel model = MakeModel();
    std::vector<StageTime> log;
    const StageLogScope scope(&log);
    model.Prepare(atm);
    ASSERT_EQ(Names(log),
              (std::vector<std::string>{"hillaire/transmittance", "hillaire/multiple-scattering"}));
    EXPECT_EQ(log[0].items, kHillaireTransmittanceWidth * kHillaireTransmittanceHeight);
    EXPECT_EQ(log[1].items, kHillaireMsSize * kHillaireMsSize);
    for (const StageTime& t : log) {
        EXPECT_EQ(t.backend, "cpu");
        EXPECT_GE(t.kernel_ms, 0.0);
    }

    // A render inside the atmosphere builds its frame tables as stages...
    log.clear();
    RenderRequest request = atmos_test::QuietRequest(GetView("ground-sunrise", atm), 16, 9);
    Image image;
    model.Render(request, &image);
    // (the one launch log: the render's own launch follows its tables)
    ASSERT_EQ(Names(log), (std::vector<std::string>{"hillaire/sky-view",
                                                    "hillaire/aerial-perspective", "render"}));
    EXPECT_EQ(log[0].items, kHillaireSkyViewWidth * kHillaireSkyViewHeight);
    EXPECT_EQ(log[1].items, kHillaireApSize * kHillaireApSize);

    // ... one outside it none (ray march), and Sample no table: each query
    // computes the sky-view texels it reads (issue 33), all queries through
    // the one launch.
    log.clear();
    request.view = GetView("space", atm);
    model.Render(request, &image);
    EXPECT_EQ(Names(log), (std::vector<std::string>{"render"}));
    log.clear();
    const std::vector<SampleQuery> queries = {{0.0, 0.5, 0.2, 60.0},
                                              {0.0, -0.1, 0.2, 60.0},
                                              {1e3, 0.5, 0.2, 60.0},
                                              {200e3, 0.5, 0.2, 60.0}};
    (void)model.Sample(queries);
    EXPECT_EQ(Names(log), (std::vector<std::string>{"sample"}));
}

// The wide channel batches' stages (CPU only) are in the stage log too:
// PrepareWide's two tables, a frame's sky-view and aerial-perspective tables.
TEST(HillaireStages, WideStagesAreLogged) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
    const std::vector<AtmosphereParameters> batches = {spectral.AtWavelengths(680, 550, 440),
                                                       spectral.AtWavelengths(620, 500, 410)};
    HillaireModel model = MakeModel();
    std::vector<StageTime> log;
    const StageLogScope scope(&log);
    model.PrepareWide(batches);
    ASSERT_EQ(Names(log), (std::vector<std::string>{"hillaire/wide-transmittance",
                                                    "hillaire/wide-multiple-scattering"}));
    EXPECT_EQ(log[0].items, kHillaireTransmittanceWidth * kHillaireTransmittanceHeight);
    EXPECT_EQ(log[1].items, kHillaireMsSize * kHillaireMsSize);
    for (const StageTime& t : log) EXPECT_EQ(t.backend, "cpu");
    log.clear();
    const RenderRequest request =
        atmos_test::QuietRequest(GetView("ground-sunrise", batches[0]), 16, 9);
    std::vector<float> values;
    model.RenderWide(request, &values);
    ASSERT_EQ(Names(log), (std::vector<std::string>{"hillaire/wide-sky-view",
                                                    "hillaire/wide-aerial-perspective"}));
    EXPECT_EQ(log[0].items, kHillaireSkyViewWidth * kHillaireSkyViewHeight);
    EXPECT_EQ(log[1].items, kHillaireApSize * kHillaireApSize);
}

// The stages write only their own texels, so the tables do not depend on the
// schedule: one thread and all threads give bit-identical tables.
TEST(HillaireStages, TablesDoNotDependOnTheThreadCount) {
    const AtmosphereParameters atm = EarthAtmosphere();
    HillaireModel a = MakeModel(), b = MakeModel();
    a.Prepare(atm);
    {
        const ThreadLimit one(1);
        b.Prepare(atm);
    }
    const View view = GetView("plane-sunrise", atm);
    const auto fa = a.BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0, true);
    std::unique_ptr<HillaireFrame> fb;
    {
        const ThreadLimit one(1);
        fb = b.BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0, true);
    }
    const auto same = [](const Table& x, const Table& y) {
        ASSERT_EQ(x.size(), y.size());
        ASSERT_GT(x.size(), 0u);
        for (size_t i = 0; i < x.size(); ++i) ASSERT_EQ(x.data()[i], y.data()[i]) << i;
    };
    same(a.transmittance_table(), b.transmittance_table());
    same(a.multiple_scattering_table(), b.multiple_scattering_table());
    same(fa->sky_view, fb->sky_view);
    same(fa->ap_scatter, fb->ap_scatter);
    same(fa->ap_transmittance, fb->ap_transmittance);
}

}  // namespace
}  // namespace atmos
