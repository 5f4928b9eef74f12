// Tests of the `hillaire` model (Hillaire 2020): its tables against direct
// numerical integration, the table paths against the ray march they sample,
// and its single-scattering part against the `naive` model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "models/hillaire.h"
#include "models/naive.h"
#include "physics/transmittance.h"
#include "render/render.h"

namespace atmos {
namespace {

std::unique_ptr<HillaireModel> MakeModel(const AtmosphereParameters& atm,
                                         const std::map<std::string, std::string>& given = {}) {
    const HillaireOptions options = HillaireModel::OptionRows().Parse("hillaire", given);
    auto model = std::make_unique<HillaireModel>(options);
    model->Prepare(atm);
    return model;
}

// One prepared model on the canonical atmosphere, shared by the tests.
const HillaireModel& EarthModel() {
    static const std::unique_ptr<HillaireModel> model = MakeModel(EarthAtmosphere());
    return *model;
}

Vec3d Dir(double mu, double az = 0.0) {
    const double s = std::sqrt(Max(0.0, 1.0 - mu * mu));
    return Vec3d(s * std::cos(az), s * std::sin(az), mu);
}

double RelErr(double a, double b) { return std::fabs(a - b) / Max(std::fabs(b), 1e-30); }

// Largest |T_table - exp(-tau_direct)| over texel centres (`centres`) or over
// (r, mu) between texels; tau_direct by the trapezoid rule, 4000 intervals.
double TransmittanceError(const HillaireModel& model, bool centres) {
    const HillaireEvaluator e = model.MakeEvaluator();
    const AtmosphereParameters& atm = model.atmosphere();
    double worst = 0.0;
    auto check = [&](double r, double mu) {
        const Vec3d tau = OpticalDepthToTopAtmosphereBoundary(atm, r, mu, 4000);
        const Vec3d t = e.Transmittance(r, mu);
        for (int c = 0; c < 3; ++c) worst = Max(worst, std::fabs(t[c] - std::exp(-tau[c])));
    };
    if (centres) {
        for (int j = 0; j < kHillaireTransmittanceHeight; j += 9) {
            for (int i = 0; i < kHillaireTransmittanceWidth; i += 17) {
                double r, mu;
                HillaireTransmittanceRMu(atm, i / 255.0, j / 63.0, &r, &mu);
                check(r, mu);
            }
        }
    } else {
        for (double h : {0.0, 300.0, 2500.0, 11e3, 33e3, 77e3}) {
            for (double mu : {1.0, 0.7, 0.3, 0.1, 0.03, 0.0, -0.05}) {
                const double r = atm.bottom_radius + h;
                if (!RayIntersectsGround(r, mu, atm.bottom_radius)) check(r, mu);
            }
        }
    }
    return worst;
}

TEST(Hillaire, TableMappingsInvertEachOther) {
    const AtmosphereParameters atm = EarthAtmosphere();
    // Transmittance: unit (x_mu, x_r) -> (r, mu) -> texture uv on the texel centres.
    for (int j = 0; j < kHillaireTransmittanceHeight; j += 7) {
        for (int i = 0; i < kHillaireTransmittanceWidth; i += 15) {
            double r, mu, u, v;
            HillaireTransmittanceRMu(atm, i / 255.0, j / 63.0, &r, &mu);
            HillaireTransmittanceUv(atm, r, mu, &u, &v);
            EXPECT_NEAR(u, (i + 0.5) / kHillaireTransmittanceWidth, 1e-6);
            EXPECT_NEAR(v, (j + 0.5) / kHillaireTransmittanceHeight, 1e-9);
        }
    }
    // Sky-view: the horizon sits at v = 0.5 and texels crowd around it.
    for (double h : {0.0, 5000.0, 60e3}) {
        const double r = atm.bottom_radius + h;
        for (int j = 0; j < kHillaireSkyViewHeight; j += 5) {
            for (int i = 0; i < kHillaireSkyViewWidth; i += 11) {
                double mu_v, cos_az, u, v;
                HillaireSkyViewParams(r, atm.bottom_radius, i / 191.0, j / 107.0, &mu_v, &cos_az);
                HillaireSkyViewUv(r, atm.bottom_radius, mu_v, cos_az, &u, &v);
                EXPECT_NEAR(u, (i + 0.5) / kHillaireSkyViewWidth, 1e-6);
                EXPECT_NEAR(v, (j + 0.5) / kHillaireSkyViewHeight, 1e-6);
            }
        }
        double beta, theta_h;
        HillaireSkyViewHorizon(r, atm.bottom_radius, &beta, &theta_h);
        double u, v;
        HillaireSkyViewUv(r, atm.bottom_radius, std::cos(theta_h), 1.0, &u, &v);
        EXPECT_NEAR(v, 0.5, 1e-9);
        // Angular size of the texel rows next to the horizon vs at the zenith.
        double mu_a, mu_b, mu_z0, mu_z1, c;
        HillaireSkyViewParams(r, atm.bottom_radius, 0.0, 53.0 / 107.0, &mu_a, &c);
        HillaireSkyViewParams(r, atm.bottom_radius, 0.0, 52.0 / 107.0, &mu_b, &c);
        HillaireSkyViewParams(r, atm.bottom_radius, 0.0, 0.0, &mu_z0, &c);
        HillaireSkyViewParams(r, atm.bottom_radius, 0.0, 1.0 / 107.0, &mu_z1, &c);
        EXPECT_LT(std::acos(mu_a) - std::acos(mu_b), 0.2 * (std::acos(mu_z1) - std::acos(mu_z0)));
    }
}

TEST(Hillaire, TransmittanceTableMatchesDirectIntegration) {
    // With 500 steps the table's texel centres hold the direct integral (this
    // checks the mapping and its inverse); between texels bilinear filtering
    // adds its error. The default 40 steps (the paper's) add the midpoint rule's
    // error on long grazing paths.
    const auto fine = MakeModel(EarthAtmosphere(), {{"transmittance-steps", "500"}});
    const double fine_centre = TransmittanceError(*fine, true);
    const double fine_between = TransmittanceError(*fine, false);
    const double default_centre = TransmittanceError(EarthModel(), true);
    const double default_between = TransmittanceError(EarthModel(), false);
    std::printf(
        "transmittance |T - T_direct| max: 500 steps: centres %.1e, between %.1e; "
        "40 steps: centres %.1e, between %.1e\n",
        fine_centre, fine_between, default_centre, default_between);
    EXPECT_LT(fine_centre, 5e-5);
    EXPECT_LT(fine_between, 2e-3);
    EXPECT_LT(default_centre, 5e-3);
    EXPECT_LT(default_between, 5e-3);
}

TEST(Hillaire, MultipleScatteringIsZeroWithoutScattering) {
    AtmosphereParameters atm = EarthAtmosphere();
    atm.rayleigh_scattering = Vec3d(0.0);
    atm.mie_scattering = Vec3d(0.0);
    // (With albedo > 0 the table would hold the light the ground reflects to
    // each point, which the march multiplies by sigma_s = 0.)
    atm.ground_albedo = Vec3d(0.0);
    const auto model = MakeModel(atm);
    const Table& ms = model->multiple_scattering_table();
    for (size_t k = 0; k < ms.size(); ++k) EXPECT_EQ(ms.data()[k], 0.0f);
}

TEST(Hillaire, MultipleScatteringGrowsWithAlbedo) {
    double previous_total = -1.0;
    std::vector<float> previous;
    for (double albedo : {0.0, 0.3, 0.8}) {
        AtmosphereParameters atm = EarthAtmosphere();
        atm.ground_albedo = Vec3d(albedo);
        const auto model = MakeModel(atm);
        const Table& ms = model->multiple_scattering_table();
        double total = 0.0;
        for (size_t k = 0; k < ms.size(); ++k) {
            ASSERT_TRUE(std::isfinite(ms.data()[k]));
            ASSERT_GE(ms.data()[k], 0.0f);
            if (!previous.empty()) {
                EXPECT_GE(ms.data()[k], previous[k]) << "texel value " << k;
            }
            total += static_cast<double>(ms.data()[k]);
        }
        // Sun overhead at the ground: the lit ground adds light.
        const float* noon_ground = ms.view().data + (kHillaireMsSize - 1) * 3;
        std::printf("albedo %.1f: Psi_ms(ground, sun overhead) = %.4e %.4e %.4e\n", albedo,
                    static_cast<double>(noon_ground[0]), static_cast<double>(noon_ground[1]),
                    static_cast<double>(noon_ground[2]));
        EXPECT_GT(total, previous_total * 1.05);
        previous_total = total;
        previous.assign(ms.data(), ms.data() + ms.size());
    }
}

// An independent estimate of Psi_ms at one point: a finer quadrature of the
// same integrals (Hillaire 2020 Eq. 5-10) with optical depths integrated
// directly (no tables): 16 x 16 directions, 120 steps, 60 light steps.
Vec3d DirectPsi(const AtmosphereParameters& atm, double r, double mu_s, int kSqrt) {
    constexpr int kSteps = 120;
    const Vec3d x(0.0, 0.0, r);
    const Vec3d sun = Dir(mu_s);
    NaiveEvaluator naive;
    naive.atm = atm;
    naive.light_steps = 60;
    Vec3d l2, fms;
    for (int a = 0; a < kSqrt; ++a) {
        for (int b = 0; b < kSqrt; ++b) {
            const double phi = 2.0 * kPi * (a + 0.5) / kSqrt;
            const Vec3d dir = Dir(1.0 - 2.0 * (b + 0.5) / kSqrt, phi);
            const AtmosphereSegment seg =
                ClipToAtmosphere(x, dir, atm.bottom_radius, atm.top_radius);
            if (!seg.inside) continue;
            const double dt = (seg.t_end - seg.t_start) / kSteps;
            Vec3d tau;
            for (int s = 0; s < kSteps; ++s) {
                const Vec3d p = x + dir * (seg.t_start + (s + 0.5) * dt);
                const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
                const Vec3d ext = Extinction(atm, d);
                const Vec3d t = Exp(-(tau + ext * (0.5 * dt)));
                tau += ext * dt;
                const Vec3d sigma_s =
                    atm.rayleigh_scattering * d.rayleigh + atm.mie_scattering * d.mie;
                fms += sigma_s * t * dt;
                Vec3d tau_sun;
                if (naive.LightDepth(p, sun, &tau_sun)) {
                    l2 += sigma_s * t * Exp(-tau_sun) * (dt * IsotropicPhase());
                }
            }
        }
    }
    const double n = kSqrt * kSqrt;
    l2 = l2 / n;
    fms = fms / n;
    return Vec3d(l2.x / (1.0 - fms.x), l2.y / (1.0 - fms.y), l2.z / (1.0 - fms.z));
}

TEST(Hillaire, MultipleScatteringTableMatchesFinerQuadrature) {
    // The table with midpoint samples (--segment-offset 0.5) against the same
    // 64 directions integrated with 120 steps and direct optical depths: checks
    // the integrals and the mapping (the 20-step march per direction is within
    // a few % of 120 steps). The demo's offset 0.3 (the default before
    // issue 15) and the 64-direction estimate itself (vs 256) are reported.
    const auto mid = MakeModel(EarthAtmosphere(), {{"segment-offset", "0.5"}});
    const AtmosphereParameters& atm = mid->atmosphere();
    const Table& ms = mid->multiple_scattering_table();
    const auto demo = MakeModel(EarthAtmosphere(), {{"segment-offset", "0.3"}});
    const Table& ms_default = demo->multiple_scattering_table();
    // Texel (i, j): mu_s = -1 + 2 i / 31, altitude = 100 km j / 31.
    for (const auto& ij : {std::pair<int, int>{31, 0}, {24, 3}, {17, 0}}) {
        const double mu_s = -1.0 + 2.0 * ij.first / 31.0;
        const double r = atm.bottom_radius + 100e3 * ij.second / 31.0;
        const Vec3d ref = DirectPsi(atm, r, mu_s, 8);
        const Vec3d ref256 = DirectPsi(atm, r, mu_s, 16);
        const size_t k = static_cast<size_t>(ij.second * kHillaireMsSize + ij.first) * 3;
        for (int c = 0; c < 3; ++c) {
            const double t = static_cast<double>(ms.data()[k + static_cast<size_t>(c)]);
            const double t0 = static_cast<double>(ms_default.data()[k + static_cast<size_t>(c)]);
            std::printf(
                "Psi_ms texel (%d,%d) c%d: offset 0.5 %.4e vs direct %.4e (%.1f %%); "
                "offset 0.3 %+.1f %%; 64 vs 256 directions %+.1f %%\n",
                ij.first, ij.second, c, t, ref[c], 100.0 * RelErr(t, ref[c]),
                100.0 * (t0 / ref[c] - 1.0), 100.0 * (ref[c] / ref256[c] - 1.0));
            EXPECT_NEAR(t, ref[c], 0.05 * ref[c]);  // 20 vs 120 steps
        }
    }
}

TEST(Hillaire, SkyViewTableMatchesItsRayMarch) {
    const HillaireModel& model = EarthModel();
    const AtmosphereParameters& atm = model.atmosphere();
    HillaireEvaluator march = model.MakeEvaluator();
    march.steps = HillaireOptions().sky_view_steps;  // the sky-view table's step count
    for (double h : {0.0, 5000.0}) {
        for (double sun_elev_deg : {6.0, 45.0}) {
            // The table's rays start at least 1 m above the ground.
            const double r = atm.bottom_radius + Max(h, kHillaireSkyViewMinAltitude);
            const double mu_s = std::sin(Radians(sun_elev_deg));
            const Vec3d camera(0, 0, r);
            const Vec3d sun = Dir(mu_s);
            Camera frame = MakeCamera(camera, Vec3d(1, 0, 0), Vec3d(0, 0, 1), 60.0);
            const auto f = model.BuildFrame(frame, sun, 16.0 / 9.0, false);
            const HillaireEvaluator table = f->Evaluator();
            ASSERT_NE(table.sky_view.data, nullptr);
            // At texel centres the lookup returns the march exactly (float).
            double worst_centre = 0.0;
            for (int j = 0; j < kHillaireSkyViewHeight; j += 7) {
                for (int i = 0; i < kHillaireSkyViewWidth; i += 13) {
                    double mu_v, cos_az;
                    HillaireSkyViewParams(r, atm.bottom_radius, i / 191.0, j / 107.0, &mu_v,
                                          &cos_az);
                    const Vec3d dir = Dir(mu_v, std::acos(cos_az));
                    const Vec3d a = Vec3d(table.SkyView(camera, dir, sun));
                    const Vec3d b = Vec3d(march.Evaluate(camera, dir, sun, false).sky);
                    for (int c = 0; c < 3; ++c) {
                        worst_centre = Max(worst_centre, RelErr(a[c], b[c]));
                    }
                }
            }
            // Between texels, above the horizon: bilinear interpolation error.
            double worst_between = 0.0, sum_between = 0.0;
            int n = 0;
            for (double elev = 0.5; elev < 90.0; elev += 3.7) {
                for (double az = 1.3; az < 180.0; az += 7.9) {
                    const Vec3d dir = Dir(std::sin(Radians(elev)), Radians(az));
                    const RayResult a = table.Evaluate(camera, dir, sun, false);
                    const RayResult b = march.Evaluate(camera, dir, sun, false);
                    for (int c = 0; c < 3; ++c) {
                        const double e = RelErr(a.sky[c], b.sky[c]);
                        worst_between = Max(worst_between, e);
                        sum_between += e;
                        ++n;
                    }
                }
            }
            std::printf(
                "sky-view vs march (default steps), h %.0f m, sun %.0f deg: texel centres max "
                "%.1e, "
                "between texels mean %.2f %% max %.2f %%\n",
                h, sun_elev_deg, worst_centre, 100.0 * sum_between / n, 100.0 * worst_between);
            EXPECT_LT(worst_centre, 1e-5);
            EXPECT_LT(sum_between / n, 0.01);
            EXPECT_LT(worst_between, 0.06);
        }
    }
}

TEST(Hillaire, SkyViewNearTheHorizonFromTheGround) {
    // A camera exactly on the ground: rays just above the horizon read the
    // table (built 1 m up) and match the march from the ground.
    const HillaireModel& model = EarthModel();
    const AtmosphereParameters& atm = model.atmosphere();
    HillaireEvaluator march = model.MakeEvaluator();
    march.steps = HillaireOptions().sky_view_steps;
    const Vec3d camera(0, 0, atm.bottom_radius);
    const Vec3d sun = Dir(std::sin(Radians(3.0)));
    const auto f =
        model.BuildFrame(MakeCamera(camera, Vec3d(1, 0, 0), Vec3d(0, 0, 1), 60.0), sun, 1.0, false);
    const HillaireEvaluator table = f->Evaluator();
    double worst = 0.0;
    for (double elev : {0.005, 0.02, 0.05, 0.1, 0.3, 1.0}) {
        for (double az : {0.0, 45.0, 120.0, 180.0}) {
            const Vec3d dir = Dir(std::sin(Radians(elev)), Radians(az));
            const RayResult a = table.Evaluate(camera, dir, sun, false);
            const RayResult b = march.Evaluate(camera, dir, sun, false);
            for (int c = 0; c < 3; ++c) worst = Max(worst, RelErr(a.sky[c], b.sky[c]));
        }
    }
    std::printf("sky-view vs march just above the horizon from the ground: max %.2f %%\n",
                100.0 * worst);
    EXPECT_LT(worst, 0.03);
}

TEST(Hillaire, AerialPerspectiveMatchesDirectMarch) {
    const HillaireModel& model = EarthModel();
    const AtmosphereParameters& atm = model.atmosphere();
    const View view = GetView("plane-sunrise", atm);
    const double aspect = 16.0 / 9.0;
    const auto f = model.BuildFrame(view.camera, view.sun_direction, aspect, true);
    const HillaireEvaluator table = f->Evaluator();
    HillaireEvaluator march = model.MakeEvaluator();
    march.steps = 400;
    const Vec3d camera = view.camera.position;
    // (a) Froxel centres: the volume holds the march along the froxel's ray to
    // the slice's distance (4 segments per slice vs 400 steps here).
    double worst_centre = 0.0;
    for (int j = 1; j < kHillaireApSize; j += 5) {
        for (int i = 2; i < kHillaireApSize; i += 7) {
            const double u = (i + 0.5) / kHillaireApSize, v = (j + 0.5) / kHillaireApSize;
            const Camera& c = view.camera;
            const Vec3d dir =
                Normalize(c.forward + c.right * ((2 * u - 1) * c.tan_half_fov_y * aspect) +
                          c.up * ((1 - 2 * v) * c.tan_half_fov_y));
            const AtmosphereSegment seg =
                ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
            for (int k = 0; k < kHillaireApSize; k += 6) {
                const double d =
                    HillaireApSliceDistance(k, model.MakeEvaluator().ap_metres_per_slice);
                if (d > seg.t_end) continue;
                Vec3d L, T, Lm, Tm(1.0);
                ASSERT_TRUE(table.AerialPerspective(dir, d, &L, &T));
                march.Integrate(camera, dir, view.sun_direction, 0.0, d, 400, &Lm, &Tm);
                for (int ch = 0; ch < 3; ++ch) {
                    worst_centre = Max(worst_centre, RelErr(L[ch], Lm[ch]));
                    worst_centre = Max(worst_centre, RelErr(T[ch], Tm[ch]));
                }
            }
        }
    }
    // (b) Ground rays of the image (between froxels), against the march and
    // against the sky-view path (--ground-path sky-view).
    HillaireEvaluator sky_path = table;
    sky_path.ground_from_ap = false;
    double worst_l = 0.0, sum_l = 0.0, worst_t = 0.0, worst_sky = 0.0, sum_sky = 0.0;
    int n = 0;
    for (int y = 150; y < 270; y += 11) {
        for (int x = 3; x < 480; x += 29) {
            const Vec3d dir = view.camera.RayDirection(x, y, 480, 270);
            const AtmosphereSegment seg =
                ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
            if (!seg.hits_ground || seg.t_end > 120e3) continue;
            const RayResult a = table.Evaluate(camera, dir, view.sun_direction, false);
            const RayResult s = sky_path.Evaluate(camera, dir, view.sun_direction, false);
            const RayResult b = march.Evaluate(camera, dir, view.sun_direction, false);
            for (int c = 0; c < 3; ++c) {
                const double e = RelErr(a.sky[c], b.sky[c]);
                worst_l = Max(worst_l, e);
                sum_l += e / 3.0;
                worst_t = Max(worst_t, std::fabs(static_cast<double>(a.transmittance[c]) -
                                                 static_cast<double>(b.transmittance[c])));
                const double es = RelErr(s.sky[c], b.sky[c]);
                worst_sky = Max(worst_sky, es);
                sum_sky += es / 3.0;
            }
            ++n;
        }
    }
    std::printf(
        "aerial perspective (plane-sunrise): froxel centres vs 400-step march max %.2f %%; "
        "%d ground rays <= 120 km: in-scatter mean %.1f %% max %.1f %%, |dT| max %.3f; "
        "sky-view path: mean %.1f %% max %.1f %%\n",
        100.0 * worst_centre, n, 100.0 * sum_l / n, 100.0 * worst_l, worst_t, 100.0 * sum_sky / n,
        100.0 * worst_sky);
    EXPECT_LT(worst_centre, 0.03);
    EXPECT_GT(n, 20);
    EXPECT_LT(sum_l / n, 0.01);
    EXPECT_LT(worst_l, 0.05);
    EXPECT_LT(worst_t, 0.01);
    EXPECT_LT(sum_sky / n, 0.01);
    EXPECT_LT(worst_sky, 0.03);
}

TEST(Hillaire, LitGroundMatchesDirectIntegration) {
    // Ground radiance = a/pi (n.s) T_sun(ground) T_view, per path: aerial
    // perspective (camera inside) and march (camera in space), against optical
    // depths integrated directly.
    AtmosphereParameters atm = EarthAtmosphere();
    atm.ground_albedo = Vec3d(0.3, 0.2, 0.1);
    const auto model = MakeModel(atm);
    const Vec3d sun = Dir(std::sin(Radians(40.0)), 0.3);
    struct Case {
        Vec3d camera, forward;
    };
    const double R = atm.bottom_radius;
    for (const Case& k : {Case{Vec3d(0, 0, R + 5000.0), Normalize(Vec3d(1, 0, -0.3))},
                          Case{Vec3d(0, 0, R + 400e3), Vec3d(0, 0, -1)}}) {
        const Camera cam = MakeCamera(k.camera, k.forward, Vec3d(0, 1, 0), 60.0);
        const auto f = model->BuildFrame(cam, sun, 1.0, true);
        const HillaireEvaluator e = f->Evaluator();
        int hits = 0;
        for (int y = 2; y < 16; y += 3) {
            for (int x = 1; x < 16; x += 4) {
                const Vec3d dir = cam.RayDirection(x, y, 16, 16);
                const RayResult r = e.Evaluate(k.camera, dir, sun, true);
                const AtmosphereSegment seg =
                    ClipToAtmosphere(k.camera, dir, atm.bottom_radius, atm.top_radius);
                ASSERT_EQ(seg.hits_ground, r.hits_ground);
                if (!seg.hits_ground) continue;
                ++hits;
                const Vec3d g = k.camera + dir * seg.t_end;
                const Vec3d n = Normalize(g);
                const Vec3d tau_view = OpticalDepth(atm, k.camera + dir * seg.t_start, dir,
                                                    seg.t_end - seg.t_start, 2000);
                const Vec3d tau_sun =
                    OpticalDepthToTopAtmosphereBoundary(atm, R, Dot(n, sun), 2000);
                for (int c = 0; c < 3; ++c) {
                    const double expected = atm.ground_albedo[c] * Dot(n, sun) / kPi *
                                            std::exp(-tau_sun[c] - tau_view[c]);
                    EXPECT_NEAR(r.ground[c], expected, 0.03 * expected)
                        << "camera z " << k.camera.z << " pixel " << x << "," << y;
                }
            }
        }
        EXPECT_GE(hits, 8);
    }
}

TEST(Hillaire, NoSeamAtTheTopOfTheAtmosphere) {
    // Just inside the top the sky-view table answers; just outside, the ray
    // march (40 steps). Both must agree where they meet.
    const HillaireModel& model = EarthModel();
    const AtmosphereParameters& atm = model.atmosphere();
    for (double sun_elev_deg : {-3.0, 10.0, 60.0}) {
        const Vec3d sun = Dir(std::sin(Radians(sun_elev_deg)), 0.4);
        const Vec3d inside(0, 0, atm.top_radius - 1.0);
        const Vec3d outside(0, 0, atm.top_radius + 1.0);
        const auto f = model.BuildFrame(MakeCamera(inside, Vec3d(1, 0, 0), Vec3d(0, 0, 1), 60.0),
                                        sun, 16.0 / 9.0, false);
        const HillaireEvaluator table = f->Evaluator();
        const HillaireEvaluator march = model.MakeEvaluator();
        double worst = 0.0, sum = 0.0, peak = 0.0;
        int n = 0;
        for (double depression = 0.5; depression < 40.0; depression += 0.9) {
            for (double az = 0.0; az < 360.0; az += 30.0) {
                const Vec3d dir = Dir(-std::sin(Radians(depression)), Radians(az));
                const RayResult a = table.Evaluate(inside, dir, sun, false);
                const RayResult b = march.Evaluate(outside, dir, sun, false);
                for (int c = 0; c < 3; ++c) peak = Max(peak, static_cast<double>(b.sky[c]));
                for (int c = 0; c < 3; ++c) {
                    // Relative to the brightest value of the sweep (the darkest
                    // rays are in the planet's shadow).
                    const double e = std::fabs(a.sky[c] - b.sky[c]);
                    worst = Max(worst, e);
                    sum += e;
                    ++n;
                }
            }
        }
        std::printf(
            "seam at the top, sun %.0f deg: |L_table - L_march| / max L: mean %.2f %%, "
            "max %.2f %%\n",
            sun_elev_deg, 100.0 * sum / n / peak, 100.0 * worst / peak);
        EXPECT_GT(peak, 0.0);
        EXPECT_LT(sum / n, 0.01 * peak);
        EXPECT_LT(worst, 0.05 * peak);
    }
}

TEST(Hillaire, SingleScatteringMatchesNaive) {
    // With the multiple-scattering term off and many steps, Hillaire's march is
    // single scattering: it must match `naive` with many steps up to the
    // transmittance table's error.
    const HillaireModel& model = EarthModel();
    HillaireEvaluator h = model.MakeEvaluator();
    h.use_multiple_scattering = false;
    h.steps = 1000;
    NaiveEvaluator n;
    n.atm = model.atmosphere();
    n.steps = 1000;
    n.light_steps = 200;
    const double R = n.atm.bottom_radius;
    struct Case {
        Vec3d camera;
        double sun_elev_deg;
    };
    double worst = 0.0;
    for (const Case& k : {Case{Vec3d(0, 0, R + 10.0), 30.0}, Case{Vec3d(0, 0, R + 5000.0), 4.0},
                          Case{Vec3d(-1500e3, 0, R + 100e3), 20.0}}) {
        const Vec3d sun = Dir(std::sin(Radians(k.sun_elev_deg)), 0.2);
        for (double elev : {-20.0, -2.0, 1.0, 5.0, 20.0, 60.0, 89.0}) {
            for (double az : {0.0, 90.0, 180.0}) {
                const Vec3d up = Normalize(k.camera);
                const Vec3d east = Normalize(Cross(Vec3d(0, 1, 0), up));
                const Vec3d north = Cross(up, east);
                const double ce = std::cos(Radians(elev)), se = std::sin(Radians(elev));
                const Vec3d dir = Normalize(east * (ce * std::cos(Radians(az))) +
                                            north * (ce * std::sin(Radians(az))) + up * se);
                const RayResult a = h.Evaluate(k.camera, dir, sun, false);
                const RayResult b = n.Evaluate(k.camera, dir, sun, false);
                for (int c = 0; c < 3; ++c) {
                    if (b.sky[c] < 1e-6f) continue;
                    worst = Max(worst, RelErr(a.sky[c], b.sky[c]));
                }
            }
        }
    }
    std::printf("single scattering vs naive (1000 steps): max relative difference %.2f %%\n",
                100.0 * worst);
    EXPECT_LT(worst, 0.01);
}

TEST(Hillaire, OutputsAreFiniteAndNonNegative) {
    // Few steps: this sweep checks the paths' edge cases, not accuracy.
    const auto model_ptr = MakeModel(
        EarthAtmosphere(), {{"sky-view-steps", "3"}, {"steps", "6"}, {"ap-steps-per-slice", "1"}});
    const HillaireModel& model = *model_ptr;
    const AtmosphereParameters& atm = model.atmosphere();
    for (double h : {0.0, 1.0, 5000.0, 99999.0, 100e3, 1000e3}) {
        for (double sun_elev : {-90.0, -10.0, -1.0, 0.0, 1.0, 30.0, 90.0}) {
            const Vec3d camera(0, 0, atm.bottom_radius + h);
            const Vec3d sun = Dir(std::sin(Radians(sun_elev)), 0.7);
            const auto f = model.BuildFrame(
                MakeCamera(camera, Vec3d(1, 0, -0.2), Vec3d(0, 0, 1), 60.0), sun, 1.5, true);
            const HillaireEvaluator e = f->Evaluator();
            for (double mu = -1.0; mu <= 1.0; mu += 0.0625) {
                for (double az = 0.0; az < 6.3; az += 0.5) {
                    const RayResult r = e.Evaluate(camera, Dir(mu, az), sun, true);
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_TRUE(std::isfinite(r.sky[c]) && r.sky[c] >= 0.0f);
                        ASSERT_TRUE(std::isfinite(r.ground[c]) && r.ground[c] >= 0.0f);
                        ASSERT_TRUE(r.transmittance[c] >= 0.0f && r.transmittance[c] <= 1.0f);
                    }
                }
            }
        }
    }
}

TEST(Hillaire, BakeRoundTrip) {
    const HillaireModel& model = EarthModel();
    const std::string dir =
        (std::filesystem::path(ATMOS_TEST_TMP) / "hillaire_bake_roundtrip").string();
    std::filesystem::create_directories(dir);
    model.Bake(dir);
    const HillaireOptions options;
    HillaireModel loaded(options);
    loaded.LoadBaked(dir, EarthAtmosphere());
    const Table& a = model.transmittance_table();
    const Table& b = loaded.transmittance_table();
    ASSERT_EQ(a.size(), b.size());
    for (size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a.data()[k], b.data()[k]);
    const Table& c = model.multiple_scattering_table();
    const Table& d = loaded.multiple_scattering_table();
    ASSERT_EQ(c.size(), d.size());
    for (size_t k = 0; k < c.size(); ++k) ASSERT_EQ(c.data()[k], d.data()[k]);
    // A different atmosphere is refused with one clear error.
    AtmosphereParameters other = EarthAtmosphere();
    other.ground_albedo = Vec3d(0.3);
    HillaireModel refused(options);
    EXPECT_THROW(refused.LoadBaked(dir, other), Error);
}

TEST(Hillaire, SampleTablePathMatchesMarchPath) {
    // `sample` through the sky-view table of each query's altitude and sun against the ray
    // march of every query, both with 40 steps and midpoint samples
    // (--sky-view-steps 40, --segment-offset 0.5) so
    // that the comparison isolates the table path; with the demo's offset
    // 0.3 the 40-step march's transmittance on grazing rays is biased low
    // (printed).
    const std::map<std::string, std::string> mid = {{"segment-offset", "0.5"},
                                                    {"sky-view-steps", "40"}};
    auto with = [&](const char* path) {
        std::map<std::string, std::string> o = mid;
        o["sample-path"] = path;
        return MakeModel(EarthAtmosphere(), o);
    };
    const auto table_model = with("table");
    const auto march_model = with("march");
    const auto march_default =
        MakeModel(EarthAtmosphere(), {{"sample-path", "march"}, {"segment-offset", "0.3"}});
    std::vector<SampleQuery> queries;
    for (double mu : {1.0, 0.5, 0.2, 0.05, -0.1}) {
        for (double az : {0.0, 60.0, 180.0}) queries.push_back({1000.0, mu, 0.3, az});
    }
    queries.push_back({200e3, -0.2, 0.3, 0.0});  // from space: the march in both
    const auto a = table_model->Sample(queries);
    const auto b = march_model->Sample(queries);
    const auto b0 = march_default->Sample(queries);
    double worst_offset_t = 0.0;
    for (size_t q = 0; q < queries.size(); ++q) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(a[q].radiance[c], b[q].radiance[c], 0.03f * b[q].radiance[c] + 1e-7f)
                << "query " << q;
            EXPECT_NEAR(a[q].transmittance[c], b[q].transmittance[c],
                        0.02f * b[q].transmittance[c] + 1e-6f)
                << "query " << q;
            if (b[q].transmittance[c] > 0.0f) {
                worst_offset_t =
                    Max(worst_offset_t, RelErr(b0[q].transmittance[c], b[q].transmittance[c]));
            }
        }
    }
    std::printf("40-step march transmittance, offset 0.3 vs 0.5: max %.1f %%\n",
                100.0 * worst_offset_t);
}

// Issue 33 item 1: `sample` (sample-path=table) computes, per query, the four
// sky-view texels its lookup reads; its answer must be the bits of a lookup in
// the full sky-view table of that query's camera and sun (what a render's frame
// builds, HillaireModel::BuildFrame), however the batch is made up.
TEST(Hillaire, SamplePerQueryTexelsAreTheFrameTablesBits) {
    const auto model = MakeModel(EarthAtmosphere(), {{"sky-view-steps", "20"}});
    const AtmosphereParameters& atm = model->atmosphere();
    const std::vector<SampleQuery> queries = {{0.0, 1.0, 1.0, 0.0},       {0.0, 0.05, 0.02, 3.0},
                                              {1500.0, -0.3, 0.4, 120.0}, {12e3, 0.3, -0.1, 200.0},
                                              {0.5, 0.999, 0.7, 45.0},    {60e3, -0.8, 0.9, 359.0},
                                              {0.0, -0.02, 0.3, 180.0},   {8e3, 0.0, 0.0, 90.0}};
    const std::vector<SampleAnswer> batch = model->Sample(queries);
    for (size_t k = 0; k < queries.size(); ++k) {
        SCOPED_TRACE("query " + std::to_string(k));
        const SampleQuery& q = queries[k];
        // The camera and sun of SampleOne (render/render.h).
        const Vec3d camera(0.0, 0.0, atm.bottom_radius + q.altitude_m);
        const double sin_s = std::sqrt(std::max(0.0, 1.0 - q.mu_s * q.mu_s));
        const double az = Radians(q.azimuth_deg);
        const Vec3d sun(sin_s * std::cos(az), sin_s * std::sin(az), q.mu_s);
        const double r = Length(camera);
        Table sky_view;
        model->BuildSkyView(r, ClampCosine(Dot(sun, camera) / r), &sky_view);
        HillaireEvaluator e = model->MakeEvaluator();
        e.sky_view = sky_view.view();
        const SampleAnswer full = SampleAll(e, atm.bottom_radius, {q})[0];
        EXPECT_EQ(std::memcmp(&full, &batch[k], sizeof(SampleAnswer)), 0)
            << "full table " << full.radiance[0] << ", per-query texels " << batch[k].radiance[0];
        // Alone: the same bits as in the batch.
        const SampleAnswer alone = model->Sample({q})[0];
        EXPECT_EQ(std::memcmp(&alone, &batch[k], sizeof(SampleAnswer)), 0);
    }
}

TEST(HillaireCli, BakeThenRenderWithLoadMatchesPrepare) {
    const std::filesystem::path dir = std::filesystem::path(ATMOS_TEST_TMP) / "hillaire_cli";
    std::filesystem::create_directories(dir);
    const std::string cli = ATMOS_CLI_PATH;
    const std::string bake = (dir / "bake").string();
    const std::string a = (dir / "loaded.npy").string(), b = (dir / "prepared.npy").string();
    const std::string quiet = " --quiet 2>/dev/null";
    ASSERT_EQ(std::system((cli + " bake --model hillaire -o " + bake + quiet).c_str()), 0);
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(bake) / "hillaire.json"));
    const std::string render = cli + " render --model hillaire --view plane-sunrise --size 48x27 ";
    ASSERT_EQ(std::system((render + "--load " + bake + " -o " + a + quiet).c_str()), 0);
    ASSERT_EQ(std::system((render + "-o " + b + quiet).c_str()), 0);
    std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
    const std::string da((std::istreambuf_iterator<char>(fa)), std::istreambuf_iterator<char>());
    const std::string db((std::istreambuf_iterator<char>(fb)), std::istreambuf_iterator<char>());
    EXPECT_FALSE(da.empty());
    EXPECT_EQ(da, db);  // the baked tables are the prepared ones, bit for bit
    // A bake of another atmosphere is refused.
    EXPECT_NE(std::system(
                  (render + "--load " + bake + " --set ground_albedo=0.3 -o " + a + quiet).c_str()),
              0);
}

}  // namespace
}  // namespace atmos
