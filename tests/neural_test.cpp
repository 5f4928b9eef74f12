// Tests of the `neural` model and its training (models/neural*.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "models/naive.h"
#include "models/neural.h"
#include "models/neural_train.h"
#include "render/render.h"

namespace atmos {
namespace {

// Tiny, fast fits (well under a second each).
NeuralFitOptions TinyOptions() {
    NeuralFitOptions o;
    o.transmittance_samples = 1000;
    o.scattering_samples = 2000;
    o.transmittance_steps = 1500;
    o.scattering_steps = 1500;
    o.batch = 64;
    o.seed = 7;
    return o;
}

struct Fixture {
    AtmosphereParameters atm = EarthAtmosphere();
    std::unique_ptr<Model> reference;
    Fixture() {
        // The naive integrator as the reference: cheap to prepare and sample.
        reference = CreateModel("naive", {{"steps", "8"}, {"light-steps", "4"}});
        reference->Prepare(atm);
    }
};

Fixture& Shared() {
    static Fixture f;
    return f;
}

// Independent float64 evaluation of the stored weights (sigmoid hidden layers).
template <typename Net>
void EvaluateDouble(const Net& net, const double* in, double* out) {
    double a[64], b[64];
    for (int i = 0; i < net.inputs; ++i) a[i] = in[i];
    int wo = 0, bo = 0;
    for (int l = 0; l <= net.hidden_layers; ++l) {
        const int ni = net.Width(l), no = net.Width(l + 1);
        for (int o = 0; o < no; ++o) {
            double z = static_cast<double>(net.biases[bo + o]);
            for (int i = 0; i < ni; ++i)
                z += static_cast<double>(net.weights[wo + o * ni + i]) * a[i];
            if (l < net.hidden_layers) {
                b[o] = 1.0 / (1.0 + std::exp(-z));
            } else {
                out[o] = net.output == NeuralOutput::kSigmoid ? 1.0 / (1.0 + std::exp(-z))
                                                              : std::exp(-z);
            }
        }
        for (int o = 0; o < no; ++o) a[o] = b[o];
        wo += ni * no;
        bo += no;
    }
}

TEST(Neural, TrainingIsDeterministicForASeed) {
    Fixture& f = Shared();
    const NeuralWeights a = FitNeural(*f.reference, f.atm, TinyOptions(), nullptr);
    const NeuralWeights b = FitNeural(*f.reference, f.atm, TinyOptions(), nullptr);
    EXPECT_EQ(NeuralWeightsToJson(a), NeuralWeightsToJson(b));
    NeuralFitOptions other = TinyOptions();
    other.seed = 8;
    const NeuralWeights c = FitNeural(*f.reference, f.atm, other, nullptr);
    EXPECT_NE(NeuralWeightsToJson(a), NeuralWeightsToJson(c));
}

TEST(Neural, LossDecreasesAndHeldOutErrorIsBounded) {
    Fixture& f = Shared();
    NeuralFitReport r;
    FitNeural(*f.reference, f.atm, TinyOptions(), &r);
    ASSERT_EQ(r.scattering.loss.size(), 100u);
    ASSERT_EQ(r.transmittance.loss.size(), 100u);
    // Loss falls: the mean of the last tenth of the curve (batch losses) is
    // well below that of the first tenth.
    auto mean = [](const std::vector<double>& v, size_t a, size_t b) {
        double s = 0.0;
        for (size_t i = a; i < b; ++i) s += v[i];
        return s / static_cast<double>(b - a);
    };
    EXPECT_LT(mean(r.scattering.loss, 90, 100), 0.5 * mean(r.scattering.loss, 0, 10));
    EXPECT_LT(mean(r.transmittance.loss, 90, 100), 0.5 * mean(r.transmittance.loss, 0, 10));
    // Bounds for this small fit (1500 Adam steps on 900/1800 naive samples):
    // RMS ln-error of the held-out set below 0.6 for transmittance and 1.4 for
    // scattering (the naive reference's hard planet shadow gives zeros that a
    // small fit cannot follow in log space), and below 0.7 x that of the
    // starting point (a constant at the data's mean log level).
    EXPECT_LT(r.scattering.holdout_rms_log, 1.4);
    EXPECT_LT(r.transmittance.holdout_rms_log, 0.6);
    EXPECT_LT(r.scattering.holdout_rms_log, 0.7 * std::sqrt(mean(r.scattering.loss, 0, 10)));
    std::printf("held-out RMS ln-error: transmittance %.4f, scattering %.4f\n",
                r.transmittance.holdout_rms_log, r.scattering.holdout_rms_log);
}

TEST(Neural, SaveLoadRoundTripGivesIdenticalOutput) {
    Fixture& f = Shared();
    const NeuralWeights w = FitNeural(*f.reference, f.atm, TinyOptions(), nullptr);
    const std::string path = ::testing::TempDir() + "neural_roundtrip.json";
    {
        std::ofstream out(path);
        out << NeuralWeightsToJson(w);
    }
    std::unique_ptr<Model> m = CreateModel("neural", {{"weights", path}});
    m->Prepare(f.atm);
    const NeuralEvaluator direct = MakeNeuralEvaluator(w, f.atm);
    std::vector<SampleQuery> qs;
    for (int i = 0; i < 50; ++i) {
        SampleQuery q;
        q.altitude_m = 1000.0 * i;
        q.mu = -1.0 + 0.04 * i;
        q.mu_s = 0.9 - 0.025 * i;
        q.azimuth_deg = 3.6 * i;
        qs.push_back(q);
    }
    const std::vector<SampleAnswer> loaded = m->Sample(qs);
    const std::vector<SampleAnswer> before = SampleAll(direct, f.atm.bottom_radius, qs);
    for (size_t i = 0; i < qs.size(); ++i) {
        EXPECT_EQ(loaded[i].radiance.x, before[i].radiance.x) << i;
        EXPECT_EQ(loaded[i].radiance.z, before[i].radiance.z) << i;
        EXPECT_EQ(loaded[i].transmittance.y, before[i].transmittance.y) << i;
    }
    std::remove(path.c_str());
}

TEST(Neural, EvaluatedNetworkMatchesFloat64Evaluation) {
    for (const char* name : {"earth", "earth_large"}) {
        const NeuralWeights w = EmbeddedNeuralWeights(name);
        const AtmosphereParameters atm = EarthAtmosphere();
        const double thickness = atm.top_radius - atm.bottom_radius;
        for (int i = 0; i < 200; ++i) {
            const double alt = thickness * (i % 10) / 9.0;
            const double mu = -1.0 + 2.0 * ((i * 7) % 23) / 22.0;
            const double mu_s = -0.3 + 1.3 * ((i * 3) % 17) / 16.0;
            const double nu = -1.0 + 2.0 * ((i * 11) % 19) / 18.0;
            float xf[kNeuralMaxInputs] = {};
            NeuralEncodeScattering(w.encoding, alt, thickness, atm.bottom_radius, atm.mie_phase_g,
                                   mu, mu_s, nu, xf);
            double xd[kNeuralMaxInputs] = {};
            for (int k = 0; k < kNeuralMaxInputs; ++k) xd[k] = static_cast<double>(xf[k]);
            float sf[3];
            double sd[3];
            w.scattering.Evaluate(xf, sf);
            EvaluateDouble(w.scattering, xd, sd);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(static_cast<double>(sf[c]), sd[c], 1e-4 * sd[c] + 1e-9) << name << i;
            }
            NeuralEncodeTransmittance(alt, thickness, mu, xf);
            for (int k = 0; k < 2; ++k) xd[k] = static_cast<double>(xf[k]);
            w.transmittance.Evaluate(xf, sf);
            EvaluateDouble(w.transmittance, xd, sd);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(static_cast<double>(sf[c]), sd[c], 1e-5);
        }
    }
}

TEST(Neural, OutputsFiniteAndNonNegativeOverASweep) {
    for (const char* network : {"thesis", "large"}) {
        std::unique_ptr<Model> m = CreateModel("neural", {{"network", network}});
        const AtmosphereParameters atm = EarthAtmosphere();
        m->Prepare(atm);
        const NeuralEvaluator e = static_cast<NeuralModel*>(m.get())->MakeEvaluator();
        int n = 0;
        for (double alt : {-10.0, 0.0, 500.0, 8000.0, 60000.0, 99999.0, 100000.0, 400000.0, 4e7}) {
            for (int iv = 0; iv <= 24; ++iv) {
                const double mu = -1.0 + iv / 12.0;
                for (int is = 0; is <= 12; ++is) {
                    const double mu_s = -1.0 + is / 6.0;
                    for (double az : {0.0, 45.0, 180.0}) {
                        const double sv = std::sqrt(std::max(0.0, 1.0 - mu * mu));
                        const double ss = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
                        const double a = Radians(az);
                        const Vec3d cam(0.0, 0.0, atm.bottom_radius + alt);
                        const Vec3d dir(sv, 0.0, mu);
                        const Vec3d sun(ss * std::cos(a), ss * std::sin(a), mu_s);
                        const RayResult r = e.Evaluate(cam, Normalize(dir), Normalize(sun), true);
                        for (const Rgb& v : {r.sky, r.ground, r.transmittance}) {
                            for (float c : {v.x, v.y, v.z}) {
                                ASSERT_TRUE(std::isfinite(c)) << alt << " " << mu << " " << mu_s;
                                ASSERT_GE(c, 0.0f);
                            }
                        }
                        for (float c : {r.transmittance.x, r.transmittance.y, r.transmittance.z}) {
                            ASSERT_LE(c, 1.0f);
                        }
                        ++n;
                    }
                }
            }
        }
        EXPECT_GT(n, 5000);
    }
}

NeuralEvaluator ShippedEvaluator(const char* network) {
    std::unique_ptr<Model> m = CreateModel("neural", {{"network", network}});
    m->Prepare(EarthAtmosphere());
    return static_cast<NeuralModel*>(m.get())->MakeEvaluator();
}

TEST(Neural, ViewerOutsideTheAtmosphereIsMovedToItsBoundary) {
    // Leenman's 2025 thesis section 9.6.3: a camera in space sees what a camera where the
    // ray enters the atmosphere sees.
    const NeuralEvaluator e = ShippedEvaluator("thesis");
    const Vec3d sun = Normalize(Vec3d(0.3, 0.2, 1.0));
    for (double mu : {-0.95, -0.7, -0.55, -0.5}) {
        const Vec3d cam(0.0, 0.0, 6360e3 + 1000e3);
        const Vec3d dir(std::sqrt(1.0 - mu * mu), 0.0, mu);
        const AtmosphereSegment seg = ClipToAtmosphere(cam, dir, e.bottom, e.top);
        ASSERT_TRUE(seg.inside);
        const RayResult far = e.Evaluate(cam, dir, sun, true);
        const RayResult near = e.Evaluate(cam + dir * (seg.t_start + 1e-3), dir, sun, true);
        EXPECT_NEAR(far.sky.x, near.sky.x, 1e-4f * near.sky.x + 1e-9f) << mu;
        EXPECT_NEAR(far.transmittance.z, near.transmittance.z, 1e-4f) << mu;
    }
    // A ray that misses the atmosphere: no sky, full transmittance.
    const RayResult miss = e.Evaluate(Vec3d(0.0, 0.0, 2e7), Vec3d(1.0, 0.0, 0.0), sun, true);
    EXPECT_EQ(miss.sky.y, 0.0f);
    EXPECT_EQ(miss.transmittance.y, 1.0f);
}

TEST(Neural, SegmentTransmittanceFollowsTheNumericalIntegral) {
    // Eq. 43 with the reversed rays (section 9.6.3) against the `naive`
    // model's numerical transmittance (midpoint rule, 256 steps), for rays from
    // 10 km that hit the ground and for rays that leave through the top.
    // Bound: |ln T_neural - ln T_naive| < 0.25 for channels with T > 0.05 (0.15
    // measured with the shipped weights; their held-out RMS ln-error is 0.23).
    const NeuralEvaluator e = ShippedEvaluator("thesis");
    std::unique_ptr<Model> naive = CreateModel("naive", {{"steps", "256"}});
    naive->Prepare(EarthAtmosphere());
    const NaiveEvaluator n = static_cast<NaiveModel*>(naive.get())->MakeEvaluator();
    const Vec3d cam(0.0, 0.0, 6360e3 + 10e3);
    const Vec3d sun(0.0, 0.0, 1.0);
    int checked = 0;
    for (double mu : {-1.0, -0.7, -0.4, -0.2, 0.1, 0.4, 1.0}) {
        const Vec3d dir(std::sqrt(1.0 - mu * mu), 0.0, mu);
        const RayResult a = e.Evaluate(cam, dir, sun, false);
        const RayResult b = n.Evaluate(cam, dir, sun, false);
        EXPECT_EQ(a.hits_ground, b.hits_ground);
        for (int c = 0; c < 3; ++c) {
            const float ta = c == 0   ? a.transmittance.x
                             : c == 1 ? a.transmittance.y
                                      : a.transmittance.z;
            const float tb = c == 0   ? b.transmittance.x
                             : c == 1 ? b.transmittance.y
                                      : b.transmittance.z;
            if (tb < 0.05f) continue;
            EXPECT_LT(std::fabs(std::log(ta / tb)), 0.25f)
                << mu << " " << c << " " << ta << " " << tb;
            ++checked;
        }
    }
    EXPECT_GT(checked, 12);
}

TEST(Neural, MalformedOrMismatchedWeightsAreClearErrors) {
    const AtmosphereParameters atm = EarthAtmosphere();
    EXPECT_THROW(NeuralWeightsFromJson("{", "x"), Error);
    EXPECT_THROW(NeuralWeightsFromJson("{\"format\":\"nope\"}", "x"), Error);
    const NeuralWeights w = EmbeddedNeuralWeights("earth");
    std::string text = NeuralWeightsToJson(w);
    // Wrong input count for the encoding.
    std::string bad = text;
    const size_t p = bad.find("\"encoding\": \"thesis\"");
    ASSERT_NE(p, std::string::npos);
    bad.replace(p, std::string("\"encoding\": \"thesis\"").size(), "\"encoding\": \"extended\"");
    try {
        NeuralWeightsFromJson(bad, "bad.json");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("inputs"), std::string::npos) << e.what();
    }
    // Another atmosphere.
    AtmosphereParameters other = atm;
    other.top_radius += 10e3;
    EXPECT_THROW(CheckNeuralWeightsMatch(w, other, "earth"), Error);
    EXPECT_NO_THROW(CheckNeuralWeightsMatch(w, atm, "earth"));
    std::unique_ptr<Model> m = CreateModel("neural", {{"weights", "/nonexistent/w.json"}});
    EXPECT_THROW(m->Prepare(atm), Error);
}

TEST(Neural, WeightsCheckCoversEveryFieldTheFitDependsOn) {
    // The shipped weights were fitted to `earth` (ground albedo 0): a ground
    // albedo of 0.3 changes the reference's multiple scattering (36.7 % median
    // error, issue 15), as do the density profiles, the sun's radius and
    // mu_s_min; each is one clear error naming the field and `atmos fit`.
    const AtmosphereParameters atm = EarthAtmosphere();
    const NeuralWeights w = EmbeddedNeuralWeights("earth");
    ASSERT_TRUE(w.has_fit_atmosphere);
    EXPECT_NO_THROW(CheckNeuralWeightsMatch(w, atm, "earth"));
    AtmosphereParameters sun = atm;  // only scales the output
    sun.solar_irradiance = Vec3d(1.5, 1.6, 1.7);
    EXPECT_NO_THROW(CheckNeuralWeightsMatch(w, sun, "earth"));
    auto refused_by = [](const NeuralWeights& ww, const AtmosphereParameters& other,
                         const std::string& field) {
        try {
            CheckNeuralWeightsMatch(ww, other, "earth");
            ADD_FAILURE() << field << ": accepted";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find(field), std::string::npos) << m;
            EXPECT_NE(m.find("atmos fit"), std::string::npos) << m;
        }
    };
    auto expect_refused = [&](const AtmosphereParameters& other, const std::string& field) {
        refused_by(w, other, field);
    };
    AtmosphereParameters a = atm;
    a.ground_albedo = Vec3d(0.3);
    expect_refused(a, "ground_albedo");
    a = atm;
    a.mie_density = ExponentialProfile(2000.0);
    expect_refused(a, "mie_density");
    a = atm;
    a.rayleigh_density = ExponentialProfile(7000.0);
    expect_refused(a, "rayleigh_density");
    a = atm;
    a.absorption_density.layers[0].width *= 1.1;
    expect_refused(a, "absorption_density");
    a = atm;
    a.sun_angular_radius *= 2.0;
    expect_refused(a, "sun_angular_radius");
    a = atm;
    a.mu_s_min = -0.5;
    expect_refused(a, "mu_s_min");
    // The CLI path: the model refuses to prepare.
    std::unique_ptr<Model> m = CreateModel("neural", {});
    a = atm;
    a.ground_albedo = Vec3d(0.3);
    EXPECT_THROW(m->Prepare(a), Error);
    // Weights that do not record the whole atmosphere are refused too.
    std::string text = NeuralWeightsToJson(w);
    const NeuralWeights round = NeuralWeightsFromJson(text, "round.json");
    EXPECT_TRUE(round.has_fit_atmosphere);
    EXPECT_NO_THROW(CheckNeuralWeightsMatch(round, atm, "round.json"));
    NeuralWeights old = w;
    old.has_fit_atmosphere = false;
    const NeuralWeights old_read = NeuralWeightsFromJson(NeuralWeightsToJson(old), "old.json");
    EXPECT_FALSE(old_read.has_fit_atmosphere);
    refused_by(old_read, atm, "fit_atmosphere");
}

// The horizon band (issue 15): views within a few degrees of the horizon, sun
// up, from the ground and from 99 km, against `bruneton` (the reference the
// shipped weights were fitted to). Queries: from the ground mu = 0 (horizontal)
// to 0.05 (2.9 deg up); from 99 km mu_horizon - 0.03 (1.7 deg below: rays that
// meet the ground) to mu_horizon + 0.05 (above: the limb), and mu = 0; sun at
// mu_s 0.1 to 1 and three azimuths. The large network before issue 15
// (encoding `extended`, uniform mu, loss eps 1e-4) gave horizontal rays from
// the ground 100x too dark (median error 0.98) and horizontal rays at 99 km
// 3-4x too bright. Bruneton here has quarter-size tables (scattering-r 16,
// mu_s 16, nu 4, 50 intervals: ~2 s instead of ~15 s); on these queries it
// is within 1.2 % (median) and 9.3 % (worst) of the default.
struct HorizonBandError {
    double median = 0.0, p90 = 0.0, worst = 0.0;
    int near_zero = 0;  // answers below half the reference
    int count = 0;
};

std::vector<SampleQuery> HorizonBandQueries(double altitude_m) {
    const AtmosphereParameters atm = EarthAtmosphere();
    const double ratio = atm.bottom_radius / (atm.bottom_radius + altitude_m);
    const double mu_h = -std::sqrt(1.0 - ratio * ratio);
    std::vector<double> mus = {0.0, 0.005, 0.01, 0.02, 0.035, 0.05};
    if (altitude_m > 0.0) {
        // Around the horizon, and the horizontal ray (10 deg above it).
        mus = {mu_h - 0.03, mu_h - 0.01,  mu_h + 0.002, mu_h + 0.005, mu_h + 0.01,
               mu_h + 0.02, mu_h + 0.035, mu_h + 0.05,  0.0};
    }
    std::vector<SampleQuery> qs;
    for (double mu : mus) {
        for (double mu_s : {0.1, 0.3, 0.6, 1.0}) {
            for (double az : {0.0, 90.0, 180.0}) {
                SampleQuery q;
                q.altitude_m = altitude_m;
                q.mu = mu;
                q.mu_s = mu_s;
                q.azimuth_deg = az;
                qs.push_back(q);
            }
        }
    }
    return qs;
}

HorizonBandError HorizonBand(const std::vector<SampleAnswer>& a,
                             const std::vector<SampleAnswer>& ref) {
    std::vector<double> e;
    HorizonBandError r;
    for (size_t i = 0; i < a.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            const double b = static_cast<double>(ref[i].radiance[c]);
            const double n = static_cast<double>(a[i].radiance[c]);
            if (!(b > 0.0)) continue;
            e.push_back(std::fabs(n - b) / b);
            if (n < 0.5 * b) ++r.near_zero;
        }
    }
    std::sort(e.begin(), e.end());
    r.count = static_cast<int>(e.size());
    if (e.empty()) return r;
    r.median = e[e.size() / 2];
    r.p90 = e[e.size() * 9 / 10];
    r.worst = e.back();
    return r;
}

TEST(Neural, LargeNetworkFollowsBrunetonInTheHorizonBand) {
    const AtmosphereParameters atm = EarthAtmosphere();
    std::unique_ptr<Model> bruneton = CreateModel("bruneton", {{"scattering-r", "16"},
                                                               {"scattering-mu-s", "16"},
                                                               {"scattering-nu", "4"},
                                                               {"scattering-samples", "50"}});
    bruneton->Prepare(atm);
    std::unique_ptr<Model> large = CreateModel("neural", {{"network", "large"}});
    large->Prepare(atm);
    for (double altitude : {0.0, 99e3}) {
        const std::vector<SampleQuery> qs = HorizonBandQueries(altitude);
        const HorizonBandError e = HorizonBand(large->Sample(qs), bruneton->Sample(qs));
        std::printf(
            "horizon band at %.0f m: %d values, median %.4f, p90 %.4f, worst %.4f, "
            "below half: %d\n",
            altitude, e.count, e.median, e.p90, e.worst, e.near_zero);
        ASSERT_GT(e.count, 200);
        // Tolerance (relative, per channel): median 10 %, p90 25 %, worst 80 %
        // (the worst is a horizontal ray at 99 km, ~1e-6 per unit irradiance;
        // measured with the shipped weights: ground 0.056 / 0.143 / 0.298,
        // 99 km 0.050 / 0.180 / 0.635; before issue 15: 57 of the ground's 216
        // values below half, p90 0.97; 99 km p90 2.37, worst 4.12).
        EXPECT_EQ(e.near_zero, 0) << altitude;
        EXPECT_LT(e.median, 0.10) << altitude;
        EXPECT_LT(e.p90, 0.25) << altitude;
        EXPECT_LT(e.worst, 0.8) << altitude;
    }
}

}  // namespace
}  // namespace atmos
