// The device bookkeeping of the precomputation loop (render/stages.h), run on
// the CPU: Backend::kEmulatedDevice keeps "device" copies in host memory with
// the CUDA backend's rules (device copies kept between stages of a
// StageSession, whole outputs not uploaded, host copies stale until Download),
// poisoning with NaN whatever the device would not have. Every table-building
// model, run so, must give the CPU backend's tables bit for bit.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "base/texture.h"
#include "models/atmosphere_plus.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "models/hillaire.h"
#include "render/render.h"
#include "render/stages.h"
#include "test_util.h"

namespace atmos {
namespace {

// out = 2 * in (whole output).
struct DoubleStage : atmos_test::InOutStage {
    ATMOS_HD void operator()(int64_t i) const { out.data[i] = 2.0f * in.data[i]; }
};

// out += in (accumulated output).
struct AddStage : atmos_test::InOutStage {
    ATMOS_HD void operator()(int64_t i) const { out.data[i] += in.data[i]; }
};

// Writes only even items of a whole output.
struct HalfStage {
    TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        v(out);
    }
    ATMOS_HD void operator()(int64_t i) const {
        if (i % 2 == 0) out.data[i] = 1.0f;
    }
};

Table Filled(int n, float first) {
    Table t(n, 1, 1, 1);
    for (int i = 0; i < n; ++i) t.data()[i] = first + static_cast<float>(i);
    return t;
}

bool AllNan(const Table& t) {
    for (size_t i = 0; i < t.size(); ++i) {
        if (!std::isnan(t.data()[i])) return false;
    }
    return true;
}

bool SameBits(const Table& a, const Table& b) {
    return a.size() == b.size() &&
           std::equal(a.data(), a.data() + a.size(), b.data(),
                      [](float x, float y) { return x == y || (std::isnan(x) && std::isnan(y)); });
}

TEST(EmulatedDevice, WithoutASessionEachRunCopiesItsOutputsBack) {
    const BackendScope scope(Backend::kEmulatedDevice);
    const Table in = Filled(8, 1.0f);
    Table out(8, 1, 1, 1);
    RunStage("double", 8, 1, DoubleStage{in.view(), out.out()});
    for (int i = 0; i < 8; ++i) EXPECT_EQ(out.data()[i], 2.0f * (1.0f + i));
    RunStage("add", 8, 1, AddStage{in.view(), out.out(true)});
    for (int i = 0; i < 8; ++i) EXPECT_EQ(out.data()[i], 3.0f * (1.0f + i));
    // A whole output starts undefined on the device (NaN here): texels a stage
    // leaves unwritten come back NaN...
    Table half(8, 1, 1, 1);
    RunStage("half", 8, 1, HalfStage{half.out()});
    EXPECT_EQ(half.data()[0], 1.0f);
    EXPECT_TRUE(std::isnan(half.data()[1]));
    // ...and so does accumulating into an output not declared `accumulate`.
    Table wrong = Filled(8, 1.0f);
    RunStage("add", 8, 1, AddStage{in.view(), wrong.out()});
    EXPECT_TRUE(AllNan(wrong));
}

TEST(EmulatedDevice, ASessionKeepsTablesOnTheDeviceUntilDownload) {
    const BackendScope scope(Backend::kEmulatedDevice);
    const Table in = Filled(1000, 0.0f);
    Table mid(1000, 1, 1, 1), out(1000, 1, 1, 1);
    StageSession session;
    RunStage("double", 1000, 16, DoubleStage{in.view(), mid.out()});
    EXPECT_EQ(session.uploaded_bytes(), 4000);  // `in` only: `mid` is a whole output
    EXPECT_TRUE(AllNan(mid));                   // the host copy is stale until Download
    RunStage("double", 1000, 16, DoubleStage{mid.view(), out.out()});
    EXPECT_EQ(session.uploaded_bytes(), 4000);  // `mid` was already on the device
    EXPECT_EQ(session.downloaded_bytes(), 0);
    session.Download(&out);
    EXPECT_EQ(session.downloaded_bytes(), 4000);
    for (int i = 0; i < 1000; ++i) EXPECT_EQ(out.data()[i], 4.0f * i);
    EXPECT_TRUE(AllNan(mid));  // never downloaded: never copied
    session.Download(&mid);
    EXPECT_EQ(mid.data()[10], 20.0f);
}

TEST(EmulatedDevice, AHostWriteNeedsHostWroteAndAResizeMakesANewTable) {
    const BackendScope scope(Backend::kEmulatedDevice);
    Table in = Filled(16, 1.0f);
    Table out(16, 1, 1, 1);
    StageSession session;
    RunStage("double", 16, 1, DoubleStage{in.view(), out.out()});
    in.data()[3] = 100.0f;  // the device copy of `in` is now stale
    try {
        RunStage("double", 16, 1, DoubleStage{in.view(), out.out()});
        ADD_FAILURE() << "a host write without HostWrote was not caught";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("HostWrote"), std::string::npos) << e.what();
    }
    session.HostWrote(in);
    RunStage("double", 16, 1, DoubleStage{in.view(), out.out()});
    session.Download(&out);
    EXPECT_EQ(out.data()[3], 200.0f);
    // New storage (a new id) is a new table: uploaded afresh, no HostWrote needed.
    const uint64_t id = in.id();
    in = Filled(16, 5.0f);
    EXPECT_NE(in.id(), id);
    RunStage("double", 16, 1, DoubleStage{in.view(), out.out()});
    session.Download(&out);
    EXPECT_EQ(out.data()[0], 10.0f);
    // Writing a table whose device copy is newer would lose the device's values.
    RunStage("double", 16, 1, DoubleStage{in.view(), out.out()});
    EXPECT_THROW(session.HostWrote(out), Error);
}

// The models: tables built on the emulated device equal the CPU's bit for bit.

TEST(EmulatedDevice, HillaireTablesAndFrameMatchTheCpu) {
    const AtmosphereParameters atm = EarthAtmosphere();
    HillaireModel cpu{HillaireOptions{}};
    HillaireModel dev{HillaireOptions{}};
    cpu.Prepare(atm);
    {
        const BackendScope scope(Backend::kEmulatedDevice);
        dev.Prepare(atm);
    }
    EXPECT_TRUE(SameBits(cpu.transmittance_table(), dev.transmittance_table()));
    EXPECT_TRUE(SameBits(cpu.multiple_scattering_table(), dev.multiple_scattering_table()));
    const View view = GetView("plane-sunrise", atm);
    const auto a = cpu.BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0);
    std::unique_ptr<HillaireFrame> b;
    {
        const BackendScope scope(Backend::kEmulatedDevice);
        b = dev.BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0);
    }
    EXPECT_TRUE(SameBits(a->sky_view, b->sky_view));
    EXPECT_TRUE(SameBits(a->ap_scatter, b->ap_scatter));
    EXPECT_TRUE(SameBits(a->ap_transmittance, b->ap_transmittance));
    // `sample` through one sky-view table per (altitude, sun) group, in one session.
    std::vector<SampleQuery> queries;
    for (double alt : {0.0, 3e3, 30e3}) {
        for (double mu : {-0.2, 0.05, 0.7}) queries.push_back({alt, mu, 0.3, 40.0});
    }
    const std::vector<SampleAnswer> sa = cpu.Sample(queries);
    std::vector<SampleAnswer> sb;
    {
        const BackendScope scope(Backend::kEmulatedDevice);
        sb = dev.Sample(queries);
    }
    ASSERT_EQ(sa.size(), sb.size());
    for (size_t i = 0; i < sa.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(sa[i].radiance[c], sb[i].radiance[c]) << i;
            EXPECT_EQ(sa[i].transmittance[c], sb[i].transmittance[c]) << i;
        }
    }
}

TEST(EmulatedDevice, AtmospherePlusTablesMatchTheCpu) {
    const AtmosphereParameters atm = EarthAtmosphere();
    AplusSettings s;
    s.width = 8;
    s.height = 16;
    s.depth = 8;
    s.orders = 3;
    const AplusTables cpu = AplusPrecompute(atm, s, true);
    AplusTables dev;
    {
        const BackendScope scope(Backend::kEmulatedDevice);
        dev = AplusPrecompute(atm, s, true);
    }
    EXPECT_TRUE(SameBits(cpu.transmittance, dev.transmittance));
    EXPECT_TRUE(SameBits(cpu.scattering, dev.scattering));
    ASSERT_EQ(cpu.orders.size(), dev.orders.size());
    for (size_t k = 0; k < cpu.orders.size(); ++k) {
        EXPECT_TRUE(SameBits(cpu.orders[k], dev.orders[k])) << "order " << k + 1;
    }
}

// Bruneton on a device runs every stage per texel: the emulated device must
// give the CPU's per-texel path exactly (and, through the tests of
// bruneton_stages_test.cpp, the CPU's row path to rounding).
TEST(EmulatedDevice, BrunetonTablesMatchTheCpuTexelPath) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.3);
    BrunetonConfig c;
    c.transmittance_width = 32;
    c.transmittance_height = 8;
    c.irradiance_width = 16;
    c.irradiance_height = 4;
    c.scattering_r = 4;
    c.scattering_mu = 16;
    c.scattering_mu_s = 8;
    c.scattering_nu = 4;
    c.orders = 3;
    for (bool combined : {false, true}) {
        SCOPED_TRACE(combined ? "combined Mie" : "separate Mie");
        c.combined_mie = combined;
        BrunetonTables cpu, dev;
        std::vector<Table> cpu_density, dev_density;
        PrecomputeBrunetonWith(atm, c, true, &cpu,
                               [&](int, const BrunetonTables&, const Table* density) {
                                   if (density) cpu_density.push_back(*density);
                               });
        {
            const BackendScope scope(Backend::kEmulatedDevice);
            PrecomputeBruneton(atm, c, &dev, [&](int, const BrunetonTables&, const Table* density) {
                if (density) dev_density.push_back(*density);
            });
        }
        EXPECT_TRUE(SameBits(cpu.transmittance, dev.transmittance));
        EXPECT_TRUE(SameBits(cpu.irradiance, dev.irradiance));
        EXPECT_TRUE(SameBits(cpu.scattering, dev.scattering));
        EXPECT_TRUE(SameBits(cpu.single_mie, dev.single_mie));
        ASSERT_EQ(cpu_density.size(), dev_density.size());
        for (size_t k = 0; k < cpu_density.size(); ++k) {
            EXPECT_TRUE(SameBits(cpu_density[k], dev_density[k])) << "order " << k + 2;
        }
        for (size_t i = 0; i < dev.scattering.size(); ++i) {
            ASSERT_TRUE(std::isfinite(dev.scattering.data()[i])) << i;
        }
    }
}

// The one launch (render/render.h): renders and samples of every registered
// model on the emulated device equal the CPU's bit for bit (same model, same
// tables); a model whose evaluator has no device kernels (not in
// models/model_list.h), or whose evaluator holds a table its VisitTables does
// not name, throws here. A second render uploads nothing: the model's tables
// stay on the device.

std::vector<SampleQuery> SomeQueries() {
    std::vector<SampleQuery> queries;
    for (double alt : {0.0, 3e3, 30e3, 200e3}) {
        for (double mu : {-0.3, 0.02, 0.7}) {
            for (double mu_s : {-0.05, 0.3}) queries.push_back({alt, mu, mu_s, 40.0});
        }
    }
    return queries;
}

int64_t BytesUp(const std::vector<StageTime>& log) {
    int64_t bytes = 0;
    for (const StageTime& t : log) bytes += t.bytes_up;
    return bytes;
}

void ExpectSameImages(const Image& a, const Image& b) {
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
}

// One test per model (ctest runs them in parallel; under ASan the whole list
// in one test took 115 s).
class EveryModel : public ::testing::TestWithParam<std::string> {};

// Bit-identity between the backends does not depend on the tables' sizes:
// small tables (three orders, so the multiple-scattering loop runs twice) keep
// the precomputing models' cases to a fraction of a second.
std::string SmallTables(const std::string& name) {
    if (name == "bruneton")
        return name +
               ":orders=3:transmittance-width=32:transmittance-height=16:irradiance-width=16:"
               "irradiance-height=8:scattering-r=8:scattering-mu=16:scattering-mu-s=8:"
               "scattering-nu=4";
    if (name == "atmosphere-plus")
        return name +
               ":orders=3:table-width=8:table-height=16:table-depth=8:transmittance-width=16:"
               "transmittance-height=32";
    if (name == "hillaire") return name + ":steps=8:sky-view-steps=8:transmittance-steps=8";
    return name;
}

std::vector<std::string> ModelNames() {
    std::vector<std::string> names;
    for (const ModelInfo& info : ListModels()) names.push_back(info.name);
    return names;
}

TEST_P(EveryModel, RendersAndSamplesOnTheEmulatedDeviceAsTheCpu) {
    const AtmosphereParameters atm = EarthAtmosphere();
    const std::vector<SampleQuery> queries = SomeQueries();
    {
        std::unique_ptr<Model> model = CreateModel(ParseModelSpec(SmallTables(GetParam())));
        const ModelInfo& info = model->Info();
        model->Prepare(atm);
        for (const char* view : {"ground-noon", "ground-sunrise", "orbit-sunrise", "space"}) {
            SCOPED_TRACE(view);
            RenderRequest request;
            request.view = GetView(view, atm);
            request.width = 12;
            request.height = 7;  // (the reference: several passes, one launch each)
            request.quantity =
                info.capabilities.radiance ? Quantity::kRadiance : Quantity::kTransmittance;
            request.show_progress = false;
            Image cpu, dev, again;
            model->Render(request, &cpu);
            std::vector<StageTime> first, second;
            {
                const BackendScope scope(Backend::kEmulatedDevice);
                {
                    const StageLogScope log(&first);
                    model->Render(request, &dev);
                }
                const StageLogScope log(&second);
                model->Render(request, &again);
            }
            ExpectSameImages(cpu, dev);
            ExpectSameImages(cpu, again);
            int renders = 0;
            for (const StageTime& t : second) {
                if (t.name != "render") continue;
                ++renders;
                EXPECT_EQ(t.backend, "emulated-device");
                EXPECT_EQ(t.items, int64_t{12} * 7);
            }
            EXPECT_GE(renders, 1);
            EXPECT_EQ(BytesUp(second), 0) << "a second render uploaded tables again";
        }
        const std::vector<SampleAnswer> a = model->Sample(queries);
        std::vector<SampleAnswer> b;
        std::vector<StageTime> log;
        {
            const BackendScope scope(Backend::kEmulatedDevice);
            const StageLogScope logging(&log);
            b = model->Sample(queries);
        }
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(SampleAnswer)), 0);
        bool launched = false;
        for (const StageTime& t : log) launched = launched || t.name == "sample";
        EXPECT_TRUE(launched) << "Sample did not go through the launch";
    }
}

// Parameter names must be alphanumeric: "atmosphere-plus" -> "atmosphere_plus".
INSTANTIATE_TEST_SUITE_P(EmulatedDevice, EveryModel, ::testing::ValuesIn(ModelNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                             std::string name = p.param;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

// Tables built on the device stay there for the renders: the first render
// after an emulated Prepare uploads nothing either.
TEST(EmulatedDevice, TablesStayOnTheDeviceFromPrepareToRender) {
    const AtmosphereParameters atm = EarthAtmosphere();
    for (const char* name : {"hillaire", "atmosphere-plus"}) {
        SCOPED_TRACE(name);
        std::unique_ptr<Model> model = CreateModel(name);
        const BackendScope scope(Backend::kEmulatedDevice);
        model->Prepare(atm);
        RenderRequest request = atmos_test::QuietRequest(GetView("ground-sunrise", atm), 8, 4);
        std::vector<StageTime> log;
        const StageLogScope logging(&log);
        Image image;
        model->Render(request, &image);
        EXPECT_EQ(BytesUp(log), 0);
    }
}

// A stage (or evaluator) holding a TableView its VisitTables does not name is
// one clear error on the emulated device (the device would read host memory).
struct HidesATableStage {
    TableView named;
    TableView hidden;
    TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        v(named);
        v(out);
    }
    ATMOS_HD void operator()(int64_t i) const { out.data[i] = named.data[i] + hidden.data[i]; }
};

TEST(EmulatedDevice, ATableThatVisitTablesDoesNotNameIsAnError) {
    const Table a = Filled(8, 1.0f), b = Filled(8, 2.0f);
    Table out(8, 1, 1, 1);
    HidesATableStage stage{a.view(), b.view(), out.out()};
    RunStage("hides", 8, 1, stage);  // the CPU reads host memory: fine
    EXPECT_EQ(out.data()[0], 3.0f);
    const BackendScope scope(Backend::kEmulatedDevice);
    EXPECT_THROW(RunStage("hides", 8, 1, stage), Error);
}

}  // namespace
}  // namespace atmos
