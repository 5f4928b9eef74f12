// Wide channel batches (issue 37 item 1): a spectral run that prepares one
// model for all its batches of three and evaluates every channel per ray gives
// the values of the run with one model per batch, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "base/rng.h"
#include "harness/spectral_run.h"
#include "models/hillaire.h"
#include "physics/wide.h"
#include "test_util.h"

namespace atmos {
namespace {

// Small tables: the precomputation of 3 batches in well under a second.
const char* kSmallBruneton =
    "bruneton:orders=2:scattering-samples=20:transmittance-width=32:transmittance-height=8:"
    "irradiance-width=16:irradiance-height=4:scattering-r=8:scattering-mu=16:"
    "scattering-mu-s=8:scattering-nu=4";

// hillaire's tables have fixed sizes: few march steps instead (the
// multiple-scattering table's 64 x 20 steps per texel are fixed too). The
// second form takes the other ground and sample paths and the demo's offset.
const char* kSmallHillaire =
    "hillaire:steps=6:sky-view-steps=5:transmittance-steps=6:ap-steps-per-slice=1";
const char* kSmallHillaireOtherPaths =
    "hillaire:steps=5:sky-view-steps=4:transmittance-steps=5:ap-steps-per-slice=1:"
    "ground-path=sky-view:sample-path=march:segment-offset=0.3";

SpectralBatching Batching(bool wide) {
    SpectralBatching b;
    b.wide = wide;
    return b;
}

std::vector<SampleQuery> Queries() {
    // Random queries over altitudes, view and sun angles (low suns included,
    // where bruneton integrates single Mie along the segment), with and without
    // the ground.
    std::vector<SampleQuery> q;
    Rng rng(37, 0, 0);
    for (int i = 0; i < 64; ++i) {
        SampleQuery s;
        s.altitude_m = i % 8 == 0 ? 2e5 : 20000.0 * rng.Uniform();
        s.mu = -1.0 + 2.0 * rng.Uniform();
        s.mu_s = -0.25 + 1.25 * rng.Uniform();
        if (i % 4 == 1) s.mu_s = 0.004 * rng.Uniform();
        s.azimuth_deg = 360.0 * rng.Uniform();
        s.ground = i % 2;
        q.push_back(s);
    }
    return q;
}

void ExpectSameFloats(const std::vector<float>& a, const std::vector<float>& b) {
    ASSERT_EQ(a.size(), b.size());
    size_t differ = 0, first = a.size();
    for (size_t i = 0; i < a.size(); ++i) {
        if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) {
            if (differ++ == 0) first = i;
        }
    }
    EXPECT_EQ(differ, 0u) << "first at " << first << ": " << a[first] << " vs " << b[first];
}

class WideChannels : public ::testing::TestWithParam<const char*> {};

TEST_P(WideChannels, RenderAndSampleEqualTheThreeChannelBatchesBitForBit) {
    const ModelSpec spec = ParseModelSpec(GetParam());
    ASSERT_TRUE(UsesWideBatches(CreateModel(spec)->Info(), Batching(true)))
        << "the wide path is not taken: the comparison would be of the batches with themselves";
    const auto prepare = [](const AtmosphereParameters& a, Model* m) { m->Prepare(a); };
    // 7 wavelengths: 3 batches, the last one short (it repeats a wavelength).
    const std::vector<double> nm = {380, 420, 470, 530, 590, 660, 760};
    for (const char* preset : {"kider-2013", "earth"}) {
        SCOPED_TRACE(preset);
        const SpectralAtmosphere spectral = LoadSpectralAtmosphere(preset);
        const AtmosphereParameters rgb = LoadAtmosphere(preset);
        for (int threads : {1, 2}) {
            SCOPED_TRACE(threads);
            ThreadLimit limit(threads);
            for (const char* view : {"ground-sunrise", "plane-dawn", "space"}) {
                for (Quantity quantity : {Quantity::kRadiance, Quantity::kTransmittance}) {
                    SCOPED_TRACE(std::string(view) + " " + QuantityName(quantity));
                    RenderRequest request = atmos_test::QuietRequest(GetView(view, rgb), 20, 12);
                    request.quantity = quantity;
                    request.sun_disc = true;
                    const SpectralImage wide =
                        RenderSpectral(spec, spectral, nm, request, prepare, Batching(true));
                    const SpectralImage three =
                        RenderSpectral(spec, spectral, nm, request, prepare, Batching(false));
                    ExpectSameFloats(wide.values, three.values);
                }
            }
            const std::vector<SampleQuery> queries = Queries();
            const std::vector<double> wide =
                SampleSpectral(spec, spectral, nm, queries, {}, prepare, Batching(true));
            const std::vector<double> three =
                SampleSpectral(spec, spectral, nm, queries, {}, prepare, Batching(false));
            ASSERT_EQ(wide.size(), three.size());
            size_t differ = 0;
            for (size_t i = 0; i < wide.size(); ++i) {
                if (std::memcmp(&wide[i], &three[i], sizeof(double)) != 0) ++differ;
            }
            EXPECT_EQ(differ, 0u);
        }
    }
}

// Small tables, few steps: some view rays have optically thick steps in some
// batches only (tests/atmosphere_plus_wide_test.cpp).
const char* kSmallAtmospherePlus =
    "atmosphere-plus:table-width=8:table-height=16:table-depth=8:transmittance-width=16:"
    "transmittance-height=32:orders=3:gather-theta=6:gather-phi=12:transmittance-steps=10";

INSTANTIATE_TEST_SUITE_P(Models, WideChannels,
                         ::testing::Values(kSmallBruneton, "naive", "naive:steps=7:light-steps=5",
                                           kSmallHillaire, kSmallHillaireOtherPaths,
                                           kSmallAtmospherePlus, "oneil",
                                           "oneil:fit=original:steps=3", "schuler",
                                           "schuler:steps=5:chapman-unit=half-height", "flat",
                                           "raymarched", "raymarched:steps=3"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                             // gtest names: letters, digits and '_' only.
                             std::string name = ParseModelSpec(param.param).name;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name + std::to_string(param.index);
                         });

TEST(WideChannelBatches, BrunetonPrecomputesAllChannelsOrGathersThroughThePrepareFunction) {
    // By default the wide model precomputes every channel at once: the run's
    // prepare function is not called. With SpectralBatching::prepare_wide
    // passing it on (the CLI does when its table cache holds every batch's
    // tables) the model gathers the batches' tables through it, one call per
    // batch; the values are the same either way.
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("kider-2013");
    const std::vector<double> nm = {380, 420, 470, 530, 590, 660, 760};
    int calls = 0;
    const auto prepare = [&](const AtmosphereParameters& a, Model* m) {
        ++calls;
        m->Prepare(a);
    };
    const std::vector<SampleQuery> queries = Queries();
    const std::vector<double> at_once = SampleSpectral(ParseModelSpec(kSmallBruneton), spectral, nm,
                                                       queries, {}, prepare, Batching(true));
    EXPECT_EQ(calls, 0);
    SpectralBatching gather = Batching(true);
    int wide_calls = 0;
    gather.prepare_wide = [&](const std::vector<AtmosphereParameters>& group, Model* model,
                              const PrepareFunction& p) {
        ++wide_calls;
        model->PrepareWide(group, p);
    };
    const std::vector<double> gathered =
        SampleSpectral(ParseModelSpec(kSmallBruneton), spectral, nm, queries, {}, prepare, gather);
    EXPECT_EQ(wide_calls, 1);
    EXPECT_EQ(calls, 3);
    EXPECT_EQ(at_once, gathered);
    // A prepare function that leaves the model unprepared is refused.
    EXPECT_THROW(SampleSpectral(
                     ParseModelSpec(kSmallBruneton), spectral, nm, queries, {},
                     [](const AtmosphereParameters&, Model*) {}, gather),
                 Error);
}

TEST(WideChannelBatches, MoreWavelengthsThanOneWideModelTakes) {
    // 52 wavelengths: 18 batches, two wide groups (16 + 2).
    const ModelSpec spec = ParseModelSpec(kSmallBruneton);
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("kider-2013");
    std::vector<double> nm;
    for (int i = 0; i < 52; ++i) nm.push_back(380.0 + 8.0 * i);
    const auto prepare = [](const AtmosphereParameters& a, Model* m) { m->Prepare(a); };
    const std::vector<SampleQuery> queries = Queries();
    EXPECT_EQ(SampleSpectral(spec, spectral, nm, queries, {}, prepare, Batching(true)),
              SampleSpectral(spec, spectral, nm, queries, {}, prepare, Batching(false)));
}

TEST(WideChannelBatches, NaiveRunsTheBatchesWhereTheirShellsDiffer) {
    // A shell of 5640 km over kider-2013's air: each batch's EffectiveTopRadius
    // (where its column's optical depth ends) depends on its coefficients, so
    // the rays of the batches differ and naive's wide model runs them one by
    // one; the values are still the batches'.
    const SpectralAtmosphere spectral =
        LoadSpectralAtmosphere("kider-2013", {"top_radius=12000000"});
    const std::vector<double> nm = {380, 420, 470, 530, 590, 660, 760};
    const auto batches = SpectralBatches(nm.size(), BatchLayout::kInterleaved);
    const auto top = [&](size_t b) {
        return EffectiveTopRadius(
            spectral.AtWavelengths(nm[batches[b][0]], nm[batches[b][1]], nm[batches[b][2]]));
    };
    ASSERT_NE(top(0), top(1)) << "the shells agree: the test would not reach its case";
    const ModelSpec spec = ParseModelSpec("naive");
    const auto prepare = [](const AtmosphereParameters& a, Model* m) { m->Prepare(a); };
    std::vector<SampleQuery> queries = Queries();
    EXPECT_EQ(SampleSpectral(spec, spectral, nm, queries, {}, prepare, Batching(true)),
              SampleSpectral(spec, spectral, nm, queries, {}, prepare, Batching(false)));
    const AtmosphereParameters rgb = spectral.AtWavelengths(680, 550, 440);
    RenderRequest request = atmos_test::QuietRequest(GetView("ground-sunrise", rgb), 20, 12);
    request.sun_disc = true;
    ExpectSameFloats(RenderSpectral(spec, spectral, nm, request, prepare, Batching(true)).values,
                     RenderSpectral(spec, spectral, nm, request, prepare, Batching(false)).values);
}

TEST(WideChannelBatches, HillaireWideTablesAreTheBatchesTablesSideBySide) {
    // The transmittance and multiple-scattering tables of PrepareWide hold
    // each batch's Prepare() tables at channels 3b .. 3b + 2, bit for bit.
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("kider-2013");
    std::vector<AtmosphereParameters> batches = {spectral.AtWavelengths(380, 420, 470),
                                                 spectral.AtWavelengths(530, 590, 660),
                                                 spectral.AtWavelengths(700, 740, 780)};
    batches[1].ground_albedo = Vec3d(0.0);  // a batch without a lit ground
    const std::map<std::string, std::string> options = {{"transmittance-steps", "7"}};
    const HillaireOptions o = HillaireModel::OptionRows().Parse("hillaire", options);
    HillaireModel wide(o);
    wide.PrepareWide(batches);
    const int n = 9;
    ASSERT_EQ(wide.wide_transmittance_table().channels(), n);
    ASSERT_EQ(wide.wide_multiple_scattering_table().channels(), n);
    for (int b = 0; b < 3; ++b) {
        SCOPED_TRACE(b);
        HillaireModel three(o);
        three.Prepare(batches[b]);
        for (const auto& [narrow, wide_table] :
             {std::make_pair(&three.transmittance_table(), &wide.wide_transmittance_table()),
              std::make_pair(&three.multiple_scattering_table(),
                             &wide.wide_multiple_scattering_table())}) {
            ASSERT_EQ(narrow->width(), wide_table->width());
            ASSERT_EQ(narrow->height(), wide_table->height());
            const size_t texels = static_cast<size_t>(narrow->width()) * narrow->height();
            size_t differ = 0;
            for (size_t t = 0; t < texels; ++t) {
                for (int c = 0; c < 3; ++c) {
                    const float a = narrow->data()[t * 3 + c];
                    const float x = wide_table->data()[t * n + 3 * b + c];
                    if (std::memcmp(&a, &x, sizeof(float)) != 0) ++differ;
                }
            }
            EXPECT_EQ(differ, 0u);
        }
    }
}

TEST(WideChannelBatches, RefusesBatchesThatDifferBeyondTheirCoefficients) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("kider-2013");
    AtmosphereParameters a = spectral.AtWavelengths(400, 500, 600);
    AtmosphereParameters b = spectral.AtWavelengths(450, 550, 650);
    EXPECT_EQ(MakeWideCoefficients({a, b}).channels, 6);
    EXPECT_EQ(MakeWideCoefficients({a, b}).rayleigh_scattering[4], b.rayleigh_scattering[1]);
    b.mie_phase_g = 0.5;
    EXPECT_THROW(MakeWideCoefficients({a, b}), Error);
    EXPECT_THROW(MakeWideCoefficients({}), Error);
    EXPECT_THROW(MakeWideCoefficients(std::vector<AtmosphereParameters>(17, a)), Error);
    // A model without the capability refuses PrepareWide.
    EXPECT_THROW(CreateModel("bruneton", {{"mie-storage", "combined"}})->PrepareWide({a}), Error);
    EXPECT_FALSE(
        CreateModel("bruneton", {{"mie-storage", "combined"}})->Info().capabilities.wide_channels);
}

// Every model with wide channel batches refuses to render or sample them
// before its PrepareWide(), with an atmos::Error (not a crash or zeros).
TEST(WideChannelBatches, RenderAndSampleBeforePrepareWideThrow) {
    const AtmosphereParameters atm = EarthAtmosphere();
    const RenderRequest request = atmos_test::QuietRequest(GetView("ground-noon", atm), 8, 4);
    const std::vector<SampleQuery> queries = {{0.0, 0.5, 0.2, 60.0}};
    for (const char* name : {"bruneton", "naive", "hillaire", "atmosphere-plus", "oneil", "schuler",
                             "flat", "raymarched"}) {
        SCOPED_TRACE(name);
        std::unique_ptr<Model> model = CreateModel(name);
        ASSERT_TRUE(model->Info().capabilities.wide_channels);
        std::vector<float> values;
        EXPECT_THROW(model->RenderWide(request, &values), Error);
        EXPECT_THROW((void)model->SampleWide(queries), Error);
    }
}

// The cost study behind docs/performance.md "Wide channel batches" (slow: run
// by name, `--gtest_also_run_disabled_tests --gtest_filter='*DISABLED_Cost*'`;
// ATMOS_WIDE_COST_MODEL picks the model, default bruneton:orders=1, whose
// lookups are the default bruneton's with a fifth of its precomputation). One
// thread; CPU seconds (std::clock) of each frame and sample batch, medians of
// ATMOS_WIDE_COST_ROUNDS (default 5) rounds, each round RGB, the 40
// wavelengths in batches of three (14 prepared models) and wide (one model),
// interleaved; the models are prepared once, outside the timing.
TEST(WideChannelBatches, DISABLED_Cost) {
    const char* env_model = std::getenv("ATMOS_WIDE_COST_MODEL");
    const char* env_rounds = std::getenv("ATMOS_WIDE_COST_ROUNDS");
    const ModelSpec spec = ParseModelSpec(env_model ? env_model : "bruneton:orders=1");
    const int rounds = env_rounds ? std::atoi(env_rounds) : 5;
    ThreadLimit limit(1);
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
    const AtmosphereParameters rgb = LoadAtmosphere("earth");
    std::vector<double> nm;
    for (int i = 0; i < 40; ++i) nm.push_back(380.0 + 400.0 * i / 39.0);
    const auto batches = SpectralBatches(nm.size(), BatchLayout::kInterleaved);
    const auto cpu = [] { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; };
    double t0 = cpu();
    std::unique_ptr<Model> rgb_model = CreateModel(spec);
    rgb_model->Prepare(rgb);
    const double rgb_prepare = cpu() - t0;
    std::vector<std::unique_ptr<Model>> three;
    std::vector<AtmosphereParameters> atms;
    t0 = cpu();
    for (const auto& b : batches) {
        atms.push_back(spectral.AtWavelengths(nm[b[0]], nm[b[1]], nm[b[2]]));
        three.push_back(CreateModel(spec));
        three.back()->Prepare(atms.back());
    }
    const double three_prepare = cpu() - t0;
    std::unique_ptr<Model> wide = CreateModel(spec);
    t0 = cpu();
    wide->PrepareWide(atms);
    const double wide_prepare = cpu() - t0;
    std::printf(
        "%s prepare CPU s: rgb %.3f, 40 wavelengths in batches %.3f (x%.1f), wide %.3f "
        "(x%.1f)\n",
        spec.text.c_str(), rgb_prepare, three_prepare, three_prepare / rgb_prepare, wide_prepare,
        wide_prepare / rgb_prepare);
    const auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    const auto report = [&](const std::string& what, double units, const std::vector<double>& r,
                            const std::vector<double>& t, const std::vector<double>& w) {
        const double mr = median(r), mt = median(t), mw = median(w);
        std::printf(
            "%-16s rgb %8.1f ns, batches %9.1f ns (x%.2f), wide %9.1f ns (x%.2f); per "
            "channel: rgb %.1f, wide %.1f ns\n",
            what.c_str(), mr / units * 1e9, mt / units * 1e9, mt / mr, mw / units * 1e9, mw / mr,
            mr / units * 1e9 / 3, mw / units * 1e9 / 40);
    };
    for (const char* view : {"ground-noon", "ground-sunrise", "plane-dawn", "space"}) {
        RenderRequest request = atmos_test::QuietRequest(GetView(view, rgb), 240, 135);
        std::vector<double> r, t, w;
        for (int round = 0; round < rounds; ++round) {
            Image image;
            t0 = cpu();
            rgb_model->Render(request, &image);
            r.push_back(cpu() - t0);
            t0 = cpu();
            for (const auto& m : three) m->Render(request, &image);
            t.push_back(cpu() - t0);
            std::vector<float> values;
            t0 = cpu();
            wide->RenderWide(request, &values);
            w.push_back(cpu() - t0);
        }
        report(std::string(view) + " px", 240.0 * 135.0, r, t, w);
    }
    // Queries as bench/query_cost.py draws them (altitude 0-20 km, mu in
    // [-0.3, 1], mu_s in [-0.2, 1]).
    std::vector<SampleQuery> queries;
    Rng rng(19, 0, 0);
    for (int i = 0; i < 20000; ++i) {
        SampleQuery q;
        q.altitude_m = 20000.0 * rng.Uniform();
        q.mu = -0.3 + 1.3 * rng.Uniform();
        q.mu_s = -0.2 + 1.2 * rng.Uniform();
        q.azimuth_deg = 360.0 * rng.Uniform();
        queries.push_back(q);
    }
    std::vector<double> r, t, w;
    for (int round = 0; round < rounds; ++round) {
        t0 = cpu();
        rgb_model->Sample(queries);
        r.push_back(cpu() - t0);
        t0 = cpu();
        for (const auto& m : three) m->Sample(queries);
        t.push_back(cpu() - t0);
        t0 = cpu();
        wide->SampleWide(queries);
        w.push_back(cpu() - t0);
    }
    report("sample query", static_cast<double>(queries.size()), r, t, w);
}

}  // namespace
}  // namespace atmos
