// The reference against a published plane-parallel benchmark (issue 32 item 3):
// DISORT's test problem 2, Sweigart's (1970) Rayleigh slab, whose intensities
// are in data/benchmarks/disort_test2.csv (the source is in its header). The
// slab is emulated by a 1 km shell of constant density on a planet of radius
// 1e9 m (docs/models/reference.md "Published benchmarks": the curvature's
// effect at these angles), single-scattering albedo ssalb by an absorber of
// constant density beside the Rayleigh scattering. The published uu per unit
// beam flux pi is uu / pi per unit solar irradiance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/reference.h"
#include "physics/phase.h"
#include "render/render.h"

namespace atmos {
namespace {

constexpr double kThickness = 1000.0;  // m
constexpr double kRadius = 1e9;        // m

struct BenchmarkRow {
    std::string name;
    double tau = 0.0, ssalb = 0.0, umu0 = 0.0, phi_deg = 0.0, utau = 0.0, umu = 0.0, uu = 0.0;
};

// The fields of a data/benchmarks file's rows (comment lines start with '#';
// then the header line `header`).
std::vector<std::vector<std::string>> ReadBenchmarkCsv(const char* file, const char* header) {
    const std::filesystem::path path =
        std::filesystem::path(ATMOS_SOURCE_DIR) / "data" / "benchmarks" / file;
    std::ifstream in(path);
    EXPECT_TRUE(in.good()) << path;
    const size_t columns = std::count(header, header + std::strlen(header), ',') + 1;
    std::vector<std::vector<std::string>> rows;
    std::string line;
    bool seen_header = false;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        if (!seen_header) {
            EXPECT_EQ(line, header) << path;
            seen_header = true;
            continue;
        }
        std::stringstream fields(line);
        std::vector<std::string> f(columns);
        for (std::string& s : f) std::getline(fields, s, ',');
        rows.push_back(f);
    }
    return rows;
}

// DISORT test problem 2's published rows.
std::vector<BenchmarkRow> ReadDisortTest2() {
    std::vector<BenchmarkRow> rows;
    for (const std::vector<std::string>& f :
         ReadBenchmarkCsv("disort_test2.csv", "case,tau,ssalb,umu0,phi_deg,utau,umu,uu")) {
        BenchmarkRow r;
        r.name = f[0];
        double* numbers[7] = {&r.tau, &r.ssalb, &r.umu0, &r.phi_deg, &r.utau, &r.umu, &r.uu};
        for (int i = 0; i < 7; ++i) *numbers[i] = std::stod(f[i + 1]);
        rows.push_back(r);
    }
    return rows;
}

// A 1 km slab on a planet of radius 1e9 m: every medium of constant density,
// none scattering or absorbing yet, a black ground.
AtmosphereParameters EmptySlab() {
    AtmosphereParameters a = EarthAtmosphere();
    a.bottom_radius = kRadius;
    a.top_radius = kRadius + kThickness;
    DensityProfile constant;
    constant.layers[1].constant_term = 1.0;
    constant.layers[0] = constant.layers[1];
    a.rayleigh_scattering = Vec3d(0.0);
    a.rayleigh_density = constant;
    a.mie_scattering = a.mie_extinction = Vec3d(0.0);
    a.mie_density = constant;
    a.absorption_extinction = Vec3d(0.0);
    a.absorption_density = constant;
    a.ground_albedo = Vec3d(0.0);
    return a;
}

// The slab of optical thickness tau and single-scattering albedo ssalb:
// Rayleigh scattering ssalb tau / H and absorption (1 - ssalb) tau / H, no Mie.
AtmosphereParameters Slab(double tau, double ssalb) {
    AtmosphereParameters a = EmptySlab();
    a.rayleigh_scattering = Vec3d(ssalb * tau / kThickness);
    a.absorption_extinction = Vec3d((1.0 - ssalb) * tau / kThickness);
    ValidateAtmosphere(a);
    return a;
}

// `atmos sample`'s query for a published direction: light leaving the top
// (umu > 0) is seen from the top looking down, light reaching the ground
// (umu < 0) from the ground looking up; the view is against the light.
SampleQuery QueryFor(double umu, double umu0, double phi_deg) {
    SampleQuery q;
    q.altitude_m = umu > 0.0 ? kThickness : 0.0;
    q.mu = -umu;
    q.mu_s = umu0;
    q.azimuth_deg = phi_deg;
    return q;
}

struct Measured {
    double mean = 0.0, se = 0.0;
};

// Mean and standard error (batch means) of the query through SampleOne, the
// function `atmos sample` runs per query.
Measured Measure(const ReferenceEvaluator& base, const SampleQuery& q, int batches, int per_batch) {
    ReferenceEvaluator e = base;
    e.sample_count = per_batch;
    double sum = 0.0, sum_sq = 0.0;
    for (int b = 0; b < batches; ++b) {
        e.sample_begin = static_cast<int64_t>(b) * per_batch;
        const double v =
            static_cast<double>(SampleOne(e, kRadius, q, SampleQueryKey(q)).radiance.x);
        sum += v;
        sum_sq += v * v;
    }
    Measured m;
    m.mean = sum / batches;
    const double var =
        std::max(sum_sq / batches - m.mean * m.mean, 0.0) * batches / (batches - 1.0);
    m.se = std::sqrt(var / batches);
    return m;
}

ReferenceEvaluator Prepared(const AtmosphereParameters& atm, ReferenceEstimator estimator) {
    ReferenceOptions options;
    options.estimator = estimator;
    ReferenceModel model(options);
    model.Prepare(atm);
    return model.evaluator();  // the sun table outlives the model (SharedSunColumnTable)
}

struct Checked {
    int count = 0;
    double sum_z = 0.0;  // of (atmos - published) / standard error
};

// Checks the named cases' rows (all, or only those leaving the top) within
// max(4 standard errors, 0.5 %) of the published value; adds to `checked`.
void CheckCases(ReferenceEstimator estimator, const std::vector<std::string>& names, bool top_only,
                int batches, int per_batch, Checked* checked) {
    const std::vector<BenchmarkRow> rows = ReadDisortTest2();
    for (const std::string& name : names) {
        std::vector<BenchmarkRow> mine;
        for (const BenchmarkRow& r : rows) {
            if (r.name == name && (!top_only || r.umu > 0.0)) mine.push_back(r);
        }
        EXPECT_FALSE(mine.empty()) << name;
        if (mine.empty()) continue;
        const ReferenceEvaluator e = Prepared(Slab(mine[0].tau, mine[0].ssalb), estimator);
        for (const BenchmarkRow& r : mine) {
            const double want = r.uu / kPi;
            const Measured m = Measure(e, QueryFor(r.umu, r.umu0, r.phi_deg), batches, per_batch);
            const double tolerance = std::max(4.0 * m.se, 5e-3 * want);
            std::printf("%s umu %+.6f: published %.5e, atmos %.5e +- %.1e (%+.2f %%, z %+.2f)\n",
                        name.c_str(), r.umu, want, m.mean, m.se, 100.0 * (m.mean / want - 1.0),
                        (m.mean - want) / m.se);
            EXPECT_NEAR(m.mean, want, tolerance) << "case " << name << " umu " << r.umu;
            ++checked->count;
            checked->sum_z += (m.mean - want) / m.se;
        }
    }
}

// A bias common to the cases, each below its own tolerance, adds up: the sum
// of n independent z-scores over sqrt(n) is about normal (the batch means'
// t with 15 degrees of freedom), |.| <= 4 unless biased.
void ExpectNoCommonBias(const Checked& c) {
    const double z = c.sum_z / std::sqrt(static_cast<double>(c.count));
    std::printf("%d cases, combined z %+.2f\n", c.count, z);
    EXPECT_LE(std::abs(z), 4.0);
}

TEST(ReferenceBenchmark, DisortTest2TableIsComplete) {
    // 4 cases x 6 directions, each case's parameters as DISORT sets them.
    const std::vector<BenchmarkRow> rows = ReadDisortTest2();
    ASSERT_EQ(rows.size(), 24u);
    for (const BenchmarkRow& r : rows) {
        EXPECT_EQ(r.umu0, 0.080442);
        EXPECT_EQ(r.phi_deg, 0.0);
        EXPECT_EQ(r.utau, r.umu > 0.0 ? 0.0 : r.tau) << "emerging intensities only";
        EXPECT_GT(r.uu, 0.0);
    }
}

TEST(ReferenceBenchmark, DisortTest2HybridMatchesSweigart) {
    // The default estimator: the thin conservative slab (2B) in all six
    // directions, the thin absorbing one (2A) and the thick ones (2C, 2D) where
    // the light leaves the top (issue 32's regime: optical depth 5, a sun 85
    // degrees from the zenith). Measured: all within 0.2 % (docs/models/reference.md).
    Checked c;
    CheckCases(ReferenceEstimator::kHybrid, {"2B"}, false, 16, 2048, &c);
    CheckCases(ReferenceEstimator::kHybrid, {"2A", "2C", "2D"}, true, 16, 2048, &c);
    EXPECT_EQ(c.count, 15);
    ExpectNoCommonBias(c);
}

TEST(ReferenceBenchmark, DisortTest2TrackingMatchesSweigart) {
    // The tracking estimator where it is cheap: the thin slabs leaving the top.
    Checked c;
    CheckCases(ReferenceEstimator::kTracking, {"2A", "2B"}, true, 16, 2048, &c);
    EXPECT_EQ(c.count, 6);
    ExpectNoCommonBias(c);
}

// --- DISORT test problems 1 (isotropic) and 3 (Henyey-Greenstein), issue 32 item 4 ---
// (data/benchmarks/disort_test1_3.csv; the Mie phase kinds of the atmosphere)

struct DisortRow {
    std::string name, phase;
    double g = 0, tau = 0, ssalb = 0, umu0 = 0, fbeam_over_pi = 0, phi_deg = 0, utau = 0, umu = 0,
           uu = 0;
};

std::vector<DisortRow> ReadDisortTest13() {
    std::vector<DisortRow> rows;
    for (const std::vector<std::string>& f :
         ReadBenchmarkCsv("disort_test1_3.csv",
                          "case,phase,g,tau,ssalb,umu0,fbeam_over_pi,phi_deg,utau,umu,uu")) {
        DisortRow r;
        r.name = f[0];
        r.phase = f[1];
        double* numbers[9] = {&r.g,       &r.tau,  &r.ssalb, &r.umu0, &r.fbeam_over_pi,
                              &r.phi_deg, &r.utau, &r.umu,   &r.uu};
        for (int i = 0; i < 9; ++i) *numbers[i] = std::stod(f[i + 2]);
        rows.push_back(r);
    }
    return rows;
}

// The slab of the row: Mie scattering ssalb tau / H with the row's phase
// function and extinction tau / H, no Rayleigh, no ozone.
AtmosphereParameters MieSlab(const DisortRow& r) {
    AtmosphereParameters a = EmptySlab();
    a.mie_scattering = Vec3d(r.ssalb * r.tau / kThickness);
    a.mie_extinction = Vec3d(r.tau / kThickness);
    a.mie_phase_kind =
        r.phase == "isotropic" ? MiePhaseKind::kIsotropic : MiePhaseKind::kHenyeyGreenstein;
    a.mie_phase_g = r.g;
    ValidateAtmosphere(a);
    return a;
}

// Each named case's rows within max(4 standard errors, `floor`) of DISORT, and
// no common bias over all.
void CheckDisortCases(ReferenceEstimator estimator, const std::vector<std::string>& names,
                      int batches, int per_batch, double floor = 5e-3) {
    const std::vector<DisortRow> rows = ReadDisortTest13();
    int count = 0;
    double sum_z = 0.0;
    for (const std::string& name : names) {
        std::vector<DisortRow> mine;
        for (const DisortRow& r : rows) {
            if (r.name == name) mine.push_back(r);
        }
        ASSERT_FALSE(mine.empty()) << name;
        const ReferenceEvaluator e = Prepared(MieSlab(mine[0]), estimator);
        for (const DisortRow& r : mine) {
            const double want = r.uu / (kPi * r.fbeam_over_pi);
            const Measured m = Measure(e, QueryFor(r.umu, r.umu0, r.phi_deg), batches, per_batch);
            const double tolerance = std::max(4.0 * m.se, floor * want);
            std::printf("%s umu %+.1f: DISORT %.5e, atmos %.5e +- %.1e (%+.2f %%, z %+.2f)\n",
                        name.c_str(), r.umu, want, m.mean, m.se, 100.0 * (m.mean / want - 1.0),
                        (m.mean - want) / m.se);
            EXPECT_NEAR(m.mean, want, tolerance) << "case " << name << " umu " << r.umu;
            ++count;
            sum_z += (m.mean - want) / std::max(m.se, 1e-300);
        }
    }
    const double z = sum_z / std::sqrt(static_cast<double>(count));
    std::printf("%d directions, combined z %+.2f\n", count, z);
    EXPECT_LE(std::abs(z), 4.0);
}

TEST(ReferenceBenchmark, DisortTest1And3TableIsComplete) {
    const std::vector<DisortRow> rows = ReadDisortTest13();
    ASSERT_EQ(rows.size(), 33u);
    for (const DisortRow& r : rows) {
        EXPECT_EQ(r.utau, r.umu > 0.0 ? 0.0 : r.tau) << "emerging intensities only";
        EXPECT_GT(r.uu, 0.0);
        EXPECT_EQ(r.fbeam_over_pi * r.umu0 == 1.0 || r.fbeam_over_pi == 1.0, true);
    }
}

TEST(ReferenceBenchmark, DisortTest1MatchesVanDeHulstIsotropic) {
    // Van de Hulst's isotropic slabs: thin (absorbing and conservative) both
    // ways, the thick absorbing one leaving the top.
    CheckDisortCases(ReferenceEstimator::kHybrid, {"1A", "1B", "1D"}, 16, 1024);
}

TEST(ReferenceBenchmark, DisortTest3MatchesHenyeyGreenstein) {
    // Van de Hulst's Henyey-Greenstein slab (g = 0.75, tau 1, conservative), the
    // sun at the zenith; the tracking estimator as well. The floor is 1.5 %:
    // DISORT's answer (16 streams, HG expanded in 32 Legendre moments) is itself
    // off by up to 1.06 % (umu +1) from the exact HG slab, measured by an
    // independent plane-parallel Monte Carlo (scripts/hg_slab_mc.py, 8e6 paths per
    // direction: +0.17, +0.10, -1.06, +0.22, +0.05, +0.02 % against DISORT in the
    // file's order; docs/models/reference.md), which atmos follows.
    CheckDisortCases(ReferenceEstimator::kHybrid, {"3A"}, 16, 4096, 0.015);
    CheckDisortCases(ReferenceEstimator::kTracking, {"3A"}, 16, 1024, 0.015);
}

}  // namespace
}  // namespace atmos
