// Model `bruneton`: the precomputation's stage structs (models/bruneton_stages.h)
// on the CPU backend. The CUDA backend runs every stage per texel; the CPU
// backend replaces single and multiple scattering by their row forms (shared
// per-row work). Here both paths run on the CPU and must give the same tables:
// the same helpers in the same order of operations, so the stated bound is
// rounding: |a - b| <= 1e-5 * max(|b|, 1e-6 * max|b|) per texel and channel.
// The GPU side: tests/cuda_bruneton_stages_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "base/texture.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "models/order_check.h"
#include "render/stages.h"

namespace atmos {
namespace {

constexpr double kRelativeBound = 1e-5;

BrunetonConfig SmallConfig(int orders) {
    BrunetonConfig c;
    c.transmittance_width = 64;
    c.transmittance_height = 16;
    c.irradiance_width = 32;
    c.irradiance_height = 8;
    c.scattering_r = 6;
    c.scattering_mu = 24;
    c.scattering_mu_s = 12;
    c.scattering_nu = 5;
    c.scattering_samples = 20;
    c.orders = orders;
    return c;
}

// Worst |a - b| / max(|b|, 1e-6 * max|b|) over all floats; fails on a size
// mismatch or a table that is all zero (the comparison would prove nothing).
double WorstRelative(const Table& a, const Table& b, const std::string& what) {
    EXPECT_EQ(a.width(), b.width()) << what;
    EXPECT_EQ(a.height(), b.height()) << what;
    EXPECT_EQ(a.depth(), b.depth()) << what;
    EXPECT_EQ(a.channels(), b.channels()) << what;
    if (a.size() != b.size() || a.size() == 0) {
        ADD_FAILURE() << what << ": sizes " << a.size() << " and " << b.size();
        return 1e30;
    }
    double peak = 0.0;
    for (size_t i = 0; i < b.size(); ++i) peak = std::max(peak, std::fabs(double{b.data()[i]}));
    EXPECT_GT(peak, 0.0) << what << " is all zero";
    double worst = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        const double x = a.data()[i], y = b.data()[i];
        EXPECT_TRUE(std::isfinite(x)) << what << " float " << i;
        worst = std::max(worst, std::fabs(x - y) / std::max({std::fabs(y), 1e-6 * peak, 1e-30}));
    }
    return worst;
}

// A table whose texels vary smoothly (and differ per channel), independent of
// the model: the input of the multiple scattering stage.
Table SyntheticDensity(const BrunetonConfig& c) {
    Table t(c.scattering_nu * c.scattering_mu_s, c.scattering_mu, c.scattering_r, 3);
    for (int z = 0; z < t.depth(); ++z) {
        for (int y = 0; y < t.height(); ++y) {
            for (int x = 0; x < t.width(); ++x) {
                float* p = t.Texel(x, y, z);
                for (int ch = 0; ch < 3; ++ch) {
                    p[ch] = static_cast<float>(1e-5 * (1.5 + std::sin(0.37 * x + 0.11 * ch) +
                                                       0.5 * std::cos(0.21 * y - 0.7 * z)));
                }
            }
        }
    }
    return t;
}

BrunetonLut LutWithTransmittance(const AtmosphereParameters& atm, const BrunetonConfig& c,
                                 Table* transmittance) {
    BrunetonLut lut(atm, c);
    transmittance->Resize(c.transmittance_width, c.transmittance_height, 1, 3);
    RunStage("t", static_cast<int64_t>(c.transmittance_width) * c.transmittance_height, 16,
             BrunetonTransmittanceStage{BrunetonMappingsOnly(lut), transmittance->out()});
    lut.transmittance_table = transmittance->view();
    return lut;
}

TEST(BrunetonStages, SingleScatteringStageMatchesTheCpuRows) {
    const AtmosphereParameters atm = EarthAtmosphere();
    const BrunetonConfig c = SmallConfig(1);
    Table transmittance;
    const BrunetonLut lut = LutWithTransmittance(atm, c, &transmittance);
    Table row_r, row_m;
    ComputeBrunetonSingleScatteringRows(lut, &row_r, &row_m);
    Table st_r(row_r.width(), row_r.height(), row_r.depth(), 3);
    Table st_m(st_r);
    RunStage("single", static_cast<int64_t>(st_r.width()) * st_r.height() * st_r.depth(), 7,
             BrunetonSingleScatteringStage{lut, st_r.out(), st_m.out()});
    EXPECT_LE(WorstRelative(st_r, row_r, "single rayleigh"), kRelativeBound);
    EXPECT_LE(WorstRelative(st_m, row_m, "single mie"), kRelativeBound);
}

TEST(BrunetonStages, MultipleScatteringStageMatchesTheCpuRows) {
    const AtmosphereParameters atm = EarthAtmosphere();
    const BrunetonConfig c = SmallConfig(2);
    Table transmittance;
    const BrunetonLut lut = LutWithTransmittance(atm, c, &transmittance);
    const Table density = SyntheticDensity(c);
    Table rows;
    ComputeBrunetonMultipleScatteringRows(lut, density.view(), &rows);
    Table stage(rows.width(), rows.height(), rows.depth(), 3);
    RunStage("multiple", static_cast<int64_t>(stage.width()) * stage.height() * stage.depth(), 5,
             BrunetonMultipleScatteringStage{lut, density.view(), stage.out()});
    EXPECT_LE(WorstRelative(stage, rows, "multiple scattering"), kRelativeBound);
}

// The vectorised rows (the CPU backend's) against the scalar rows (per texel
// the stages' helpers): single scattering bit-identical (the same operations in
// the same order), on the default and the seed's quadrature, on an odd sample
// count (Simpson's 3/8 tail), a row width that is no multiple of the vector
// width, and a dense Mie layer whose rays take the thick-step weights.
size_t DifferingFloats(const Table& a, const Table& b) {
    EXPECT_EQ(a.size(), b.size());
    size_t n = 0;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
        if (std::memcmp(a.data() + i, b.data() + i, sizeof(float)) != 0) ++n;
    }
    return n;
}

std::vector<std::pair<AtmosphereParameters, BrunetonConfig>> RowCases() {
    std::vector<std::pair<AtmosphereParameters, BrunetonConfig>> cases;
    const AtmosphereParameters earth = EarthAtmosphere();
    cases.emplace_back(earth, SmallConfig(2));
    BrunetonConfig seed = SmallConfig(2);
    seed.scattering_rule = 0;
    seed.scattering_samples = 13;
    cases.emplace_back(earth, seed);
    AtmosphereParameters dense = earth;  // tests/fuzz_test.cpp's thick layer
    dense.mie_extinction = Vec3d(0.01, 0.01, 0.01);
    dense.mie_scattering = Vec3d(0.003, 0.003, 0.003);
    cases.emplace_back(dense, SmallConfig(2));
    return cases;
}

TEST(BrunetonStages, VectorSingleScatteringRowsAreBitIdenticalToTheScalarRows) {
    for (const auto& [atm, c] : RowCases()) {
        Table transmittance;
        const BrunetonLut lut = LutWithTransmittance(atm, c, &transmittance);
        Table vec_r, vec_m, ref_r, ref_m;
        ComputeBrunetonSingleScatteringRows(lut, &vec_r, &vec_m);
        ComputeBrunetonSingleScatteringRowsScalar(lut, &ref_r, &ref_m);
        EXPECT_GT(TableSum(ref_r), 0.0);
        EXPECT_EQ(DifferingFloats(vec_r, ref_r), 0u) << "rule " << c.scattering_rule;
        EXPECT_EQ(DifferingFloats(vec_m, ref_m), 0u) << "rule " << c.scattering_rule;
    }
}

// Multiple scattering: the vector rows interpolate the density along (mu, r)
// before x, the scalar rows (the renderer's lookup) x first; the same
// trilinear weights, so only float rounding differs.
TEST(BrunetonStages, VectorMultipleScatteringRowsMatchTheScalarRows) {
    double worst = 0.0;
    for (const auto& [atm, c] : RowCases()) {
        Table transmittance;
        const BrunetonLut lut = LutWithTransmittance(atm, c, &transmittance);
        const Table density = SyntheticDensity(c);
        Table vec, ref;
        ComputeBrunetonMultipleScatteringRows(lut, density.view(), &vec);
        ComputeBrunetonMultipleScatteringRowsScalar(lut, density.view(), &ref);
        worst = std::max(worst, WorstRelative(vec, ref, "multiple scattering"));
    }
    std::printf("vector vs scalar multiple scattering rows: worst relative difference %.3g\n",
                worst);
    EXPECT_LE(worst, 1e-6);
}

// The whole precomputation, per order: the CUDA backend's sequence (every
// stage per texel) run on the CPU against the CPU backend's (row forms).
struct Snapshot {
    std::vector<Table> scattering, irradiance, single_mie, density;
};
Snapshot Run(const AtmosphereParameters& atm, const BrunetonConfig& c, bool texel_stages,
             BrunetonTables* tables) {
    Snapshot s;
    PrecomputeBrunetonWith(atm, c, texel_stages, tables,
                           [&](int, const BrunetonTables& t, const Table* density) {
                               s.scattering.push_back(t.scattering);
                               s.irradiance.push_back(t.irradiance);
                               s.single_mie.push_back(t.single_mie);
                               if (density) s.density.push_back(*density);
                           });
    return s;
}

void ExpectSamePrecomputation(const AtmosphereParameters& atm, const BrunetonConfig& c) {
    double worst = 0.0;
    auto check = [&worst](const Table& a, const Table& b, const std::string& what) {
        const double w = WorstRelative(a, b, what);
        worst = std::max(worst, w);
        return w;
    };
    BrunetonTables rows_tables, texel_tables;
    const Snapshot rows = Run(atm, c, false, &rows_tables);
    const Snapshot texel = Run(atm, c, true, &texel_tables);
    ASSERT_EQ(rows.scattering.size(), static_cast<size_t>(c.orders));
    ASSERT_EQ(texel.scattering.size(), rows.scattering.size());
    ASSERT_EQ(texel.density.size(), rows.density.size());
    for (size_t o = 0; o < rows.scattering.size(); ++o) {
        const std::string order = " after order " + std::to_string(o + 1);
        EXPECT_LE(check(texel.scattering[o], rows.scattering[o], "scattering" + order),
                  kRelativeBound);
        if (o > 0) {
            EXPECT_LE(check(texel.irradiance[o], rows.irradiance[o], "irradiance" + order),
                      kRelativeBound);
            EXPECT_LE(check(texel.density[o - 1], rows.density[o - 1], "density" + order),
                      kRelativeBound);
        }
    }
    EXPECT_LE(check(texel_tables.transmittance, rows_tables.transmittance, "transmittance"),
              kRelativeBound);
    if (!c.combined_mie) {
        EXPECT_LE(check(texel_tables.single_mie, rows_tables.single_mie, "single mie"),
                  kRelativeBound);
    } else {
        EXPECT_EQ(texel_tables.single_mie.size(), 0u);
    }
    std::printf("texel stages vs CPU rows, %d orders: worst relative difference %.3g\n", c.orders,
                worst);
}

TEST(BrunetonStages, TexelStagesMatchTheCpuPathOrderByOrder) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.3, 0.3, 0.3);  // the ground bounce of the higher orders
    ExpectSamePrecomputation(atm, SmallConfig(4));
}

TEST(BrunetonStages, TexelStagesMatchTheCpuPathWithCombinedMie) {
    BrunetonConfig c = SmallConfig(3);
    c.combined_mie = true;
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.0, 0.0, 0.0);
    ExpectSamePrecomputation(atm, c);
}

TEST(BrunetonStages, EveryStageGoesThroughRunStage) {
    // Every O(table) step is a stage (so the CUDA backend runs it on the
    // device): the log names each, with its item count.
    const BrunetonConfig c = SmallConfig(3);
    std::vector<StageTime> log;
    BrunetonTables tables;
    {
        const StageLogScope scope(&log);
        PrecomputeBrunetonWith(EarthAtmosphere(), c, true, &tables);
    }
    std::map<std::string, int64_t> items;
    std::map<std::string, int> runs;
    for (const StageTime& s : log) {
        EXPECT_EQ(s.backend, "cpu");
        items[s.name] = s.items;
        ++runs[s.name];
    }
    const int64_t texels = static_cast<int64_t>(c.scattering_nu) * c.scattering_mu_s *
                           c.scattering_mu * c.scattering_r;
    const int64_t irradiance = static_cast<int64_t>(c.irradiance_width) * c.irradiance_height;
    const std::map<std::string, int64_t> expected_items = {
        {"bruneton transmittance",
         static_cast<int64_t>(c.transmittance_width) * c.transmittance_height},
        {"bruneton direct irradiance", irradiance},
        {"bruneton single scattering", texels},
        {"bruneton combine", texels},
        {"bruneton incident radiance",
         static_cast<int64_t>(kBrunetonDirections) * c.scattering_mu_s * c.scattering_r},
        {"bruneton scattering density", texels},
        {"bruneton indirect irradiance", irradiance},
        {"bruneton add irradiance", irradiance},
        {"bruneton multiple scattering", texels},
        {"bruneton accumulate", texels},
    };
    EXPECT_EQ(items, expected_items);
    EXPECT_EQ(runs["bruneton transmittance"], 1);
    EXPECT_EQ(runs["bruneton combine"], 1);
    EXPECT_EQ(runs["bruneton scattering density"], c.orders - 1);
    EXPECT_EQ(runs["bruneton accumulate"], c.orders - 1);
    EXPECT_EQ(log.size(), 4u + 6u * static_cast<size_t>(c.orders - 1));

    // The CPU backend's path logs its row forms in their place.
    log.clear();
    {
        const StageLogScope scope(&log);
        PrecomputeBrunetonWith(EarthAtmosphere(), c, false, &tables);
    }
    std::map<std::string, int64_t> row_items;
    for (const StageTime& s : log) row_items[s.name] = s.items;
    std::map<std::string, int64_t> expected_rows = expected_items;
    expected_rows.erase("bruneton single scattering");
    expected_rows.erase("bruneton multiple scattering");
    const int64_t rows = static_cast<int64_t>(c.scattering_mu) * c.scattering_r;
    expected_rows["bruneton single scattering (rows)"] = rows;
    expected_rows["bruneton multiple scattering (rows)"] = rows;
    EXPECT_EQ(row_items, expected_rows);
    EXPECT_EQ(log.size(), 4u + 6u * static_cast<size_t>(c.orders - 1));
}

// What RunStage's CUDA backend does to a stage (cuda/stage_launch.cuh), on the
// host: every table VisitTables names is copied to a new buffer (one copy per
// distinct pointer) and the stage re-pointed to the copies. Every table of
// `world` (all the tables the test holds) is then filled with NaN while the
// items run, and restored; the outputs are copied back. A stage that reads a
// table it does not name (on the device: host memory) reads NaN.
class EmulatedDevice {
  public:
    template <typename Stage>
    void Run(int64_t count, Stage stage, const std::vector<Table*>& world) {
        Repoint repoint{this};
        stage.VisitTables(repoint);
        std::vector<std::vector<float>> saved;
        for (Table* t : world) {
            saved.emplace_back(t->data(), t->data() + t->size());
            std::fill(t->data(), t->data() + t->size(), std::nanf(""));
        }
        for (int64_t i = 0; i < count; ++i) stage(i);
        for (size_t k = 0; k < world.size(); ++k) {
            std::copy(saved[k].begin(), saved[k].end(), world[k]->data());
        }
        for (Buffer& b : buffers_) {
            if (b.output) std::copy(b.copy.begin(), b.copy.end(), b.host);
        }
        buffers_.clear();
    }

  private:
    struct Buffer {
        float* host;
        std::vector<float> copy;
        bool output;
    };
    float* Copy(const float* host, size_t floats, bool output) {
        if (!host) return nullptr;
        for (Buffer& b : buffers_) {
            if (b.host == host) {
                b.output = b.output || output;
                return b.copy.data();
            }
        }
        buffers_.push_back(
            {const_cast<float*>(host), std::vector<float>(host, host + floats), output});
        return buffers_.back().copy.data();
    }
    struct Repoint {
        EmulatedDevice* device;
        void operator()(TableView& v) const {
            v.data = device->Copy(
                v.data,
                static_cast<size_t>(v.width) * v.height * v.depth * static_cast<size_t>(v.channels),
                false);
        }
        void operator()(TableOut& o) const { o.data = device->Copy(o.data, o.size(), true); }
    };
    std::deque<Buffer> buffers_;  // stable addresses while the stage runs
};

// Runs `make(out)` on the CPU backend and `make(out_emulated)` through
// EmulatedDevice (the same table shape and start values), then expects equal,
// finite tables.
template <typename MakeStage>
void ExpectStageNamesItsTables(const char* name, int64_t count, Table* out, Table* out_emulated,
                               const std::vector<Table*>& world, MakeStage make) {
    SCOPED_TRACE(name);
    RunStage(name, count, 16, make(out));
    std::vector<Table*> others;
    for (Table* t : world) {
        if (t != out && t != out_emulated) others.push_back(t);
    }
    EmulatedDevice().Run(count, make(out_emulated), others);
    ASSERT_EQ(out->size(), out_emulated->size());
    size_t differ = 0, not_finite = 0;
    for (size_t i = 0; i < out->size(); ++i) {
        if (!std::isfinite(out_emulated->data()[i])) ++not_finite;
        if (!(out->data()[i] == out_emulated->data()[i])) ++differ;
    }
    EXPECT_EQ(not_finite, 0u);
    EXPECT_EQ(differ, 0u);
}

TEST(BrunetonStages, EachStageReadsOnlyTheTablesItNames) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.3, 0.3, 0.3);
    const BrunetonConfig c = SmallConfig(3);
    const int width = c.scattering_nu * c.scattering_mu_s;
    const int64_t texels = static_cast<int64_t>(width) * c.scattering_mu * c.scattering_r;
    const int64_t irr_texels = static_cast<int64_t>(c.irradiance_width) * c.irradiance_height;
    BrunetonLut lut(atm, c);
    const BrunetonLut mappings = BrunetonMappingsOnly(lut);

    // Every table of the test (pairs: CPU run, emulated run), all poisoned
    // during each emulated run but the stage's own copies.
    const Table s3(width, c.scattering_mu, c.scattering_r, 3);
    const Table irr0(c.irradiance_width, c.irradiance_height, 1, 3);
    Table t(c.transmittance_width, c.transmittance_height, 1, 3), t2(t);
    Table e(irr0), e2(irr0), ray(s3), ray2(s3), mie(s3), mie2(s3), single_mie(s3);
    Table scat(width, c.scattering_mu, c.scattering_r, 4), scat2(scat);
    Table directions = MakeBrunetonDirectionTable();
    Table multiple = SyntheticDensity(c);
    Table inc(3 * kBrunetonDirections, c.scattering_mu_s, c.scattering_r, 1), inc2(inc);
    Table j(s3), j2(s3), irr(irr0), irr2(irr0), total(irr0), total2(irr0), ms(s3), ms2(s3);
    Table acc(scat), acc2(scat);
    const std::vector<Table*> world = {
        &t,    &t2,    &e,          &e2,       &ray, &ray2, &mie, &mie2, &single_mie,
        &scat, &scat2, &directions, &multiple, &inc, &inc2, &j,   &j2,   &irr,
        &irr2, &total, &total2,     &ms,       &ms2, &acc,  &acc2};

    ExpectStageNamesItsTables("transmittance", static_cast<int64_t>(t.width()) * t.height(), &t,
                              &t2, world, [&](Table* o) {
                                  return BrunetonTransmittanceStage{mappings, o->out()};
                              });
    lut.transmittance_table = t.view();

    ExpectStageNamesItsTables("direct irradiance", irr_texels, &e, &e2, world, [&](Table* o) {
        return BrunetonDirectIrradianceStage{lut, o->out()};
    });

    // Single scattering writes two tables: Mie is compared after the call.
    ExpectStageNamesItsTables("single scattering", texels, &ray, &ray2, world, [&](Table* o) {
        return BrunetonSingleScatteringStage{lut, o->out(), (o == &ray ? mie : mie2).out()};
    });
    EXPECT_TRUE(std::equal(mie.data(), mie.data() + mie.size(), mie2.data()));

    ExpectStageNamesItsTables("combine", texels, &scat, &scat2, world, [&](Table* o) {
        return BrunetonCombineStage{ray.view(), mie.view(), o->out(), single_mie.out()};
    });

    for (int order : {2, 3}) {
        ExpectStageNamesItsTables(
            "incident", static_cast<int64_t>(kBrunetonDirections) * inc.height() * inc.depth(),
            &inc, &inc2, world, [&](Table* o) {
                BrunetonIncidentStage s;
                s.lut = lut;
                if (order == 2) {
                    s.single_rayleigh = ray.view();
                    s.single_mie = mie.view();
                } else {
                    s.multiple = multiple.view();
                }
                s.ground_irradiance = e.view();
                s.directions = directions.view();
                s.order = order;
                s.incident = o->out();
                return s;
            });
        ExpectStageNamesItsTables("density", texels, &j, &j2, world, [&](Table* o) {
            return BrunetonDensityStage{mappings, inc.view(), directions.view(), o->out()};
        });
    }

    for (int order : {1, 2}) {
        ExpectStageNamesItsTables("indirect irradiance", irr_texels, &irr, &irr2, world,
                                  [&](Table* o) {
                                      BrunetonIndirectIrradianceStage s;
                                      s.lut = mappings;
                                      s.order = order;
                                      if (order == 1) {
                                          s.single_rayleigh = ray.view();
                                          s.single_mie = mie.view();
                                      } else {
                                          s.multiple = multiple.view();
                                      }
                                      s.out = o->out();
                                      return s;
                                  });
    }

    total = e;
    total2 = e;
    ExpectStageNamesItsTables("add", irr_texels, &total, &total2, world, [&](Table* o) {
        return BrunetonAddStage{e.view(), o->out()};
    });

    ExpectStageNamesItsTables("multiple scattering", texels, &ms, &ms2, world, [&](Table* o) {
        return BrunetonMultipleScatteringStage{lut, multiple.view(), o->out()};
    });

    acc = scat;
    acc2 = scat;
    ExpectStageNamesItsTables("accumulate", texels, &acc, &acc2, world, [&](Table* o) {
        return BrunetonAccumulateStage{mappings, ms.view(), o->out()};
    });
}

TEST(BrunetonStages, DirectionTableCoversTheSphere) {
    // The 512 midpoint directions are unit vectors whose solid angles add up to
    // the midpoint rule's 4 pi: the 16 theta midpoints sum sin to
    // 1 / sin(pi/32), so the total is 4 pi (pi/32) / sin(pi/32), 1.6e-3 above
    // 4 pi.
    const Table t = MakeBrunetonDirectionTable();
    const BrunetonDirections d(t.view());
    double total = 0.0;
    for (int k = 0; k < kBrunetonDirections; ++k) {
        const double x = d.wx[k], y = d.wy[k], z = d.wz[k];
        EXPECT_NEAR(x * x + y * y + z * z, 1.0, 1e-6) << k;
        total += double{d.solid_angle[k]};
    }
    const double expected = 4.0 * kPi * (kPi / 32.0) / std::sin(kPi / 32.0);
    EXPECT_NEAR(total, expected, 1e-5 * expected);
}

}  // namespace
}  // namespace atmos
