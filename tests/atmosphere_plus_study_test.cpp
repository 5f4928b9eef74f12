// The question Boody's Atmosphere Plus notes section 2.4 leaves open, measured: which
// parameterization and table size gives the lowest error for a memory budget.
//
// Not part of the default run (minutes of work): run it with
//   build/tests/atmos_tests --gtest_also_run_disabled_tests
//       --gtest_filter='AtmospherePlusStudy.*'
// It prints the markdown table of docs/models/atmosphere-plus.md.
//
// Stand-in reference: the same model's order-1 quantity evaluated by direct
// integration at each pixel's exact (h, mu, mu_s) (AtmospherePlusDirectEvaluator:
// same physics, same 30-step trapezoidal rule, same omitted azimuth, no table),
// so the error is the table's alone (parameterization + size + interpolation).
// FLIP against the path-traced reference replaces it when the harness lands.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/view.h"
#include "models/atmosphere_plus.h"
#include "render/render.h"
#include "test_util.h"

namespace atmos {
namespace {

constexpr int kW = 96, kH = 54;

struct Errors {
    double rel_rmse = 0.0;      // sqrt(mean |a-b|^2) / sqrt(mean |b|^2), linear radiance
    double display_rmse = 0.0;  // RMSE after exposure, 1 - exp(-x), ^(1/2.2), in [0, 1]
};

std::vector<Rgb> RenderWith(const AtmospherePlusEvaluator* table,
                            const AtmospherePlusDirectEvaluator* direct,
                            const AtmosphereParameters& atm, const View& view) {
    RenderRequest request = atmos_test::QuietRequest(view, kW, kH);
    const PixelSetup setup = MakePixelSetup(request, atm);
    Image image;
    image.Resize(kW, kH);
    if (table) RenderImage(*table, setup, image.View(), false);
    if (direct) RenderImage(*direct, setup, image.View(), false);
    std::vector<Rgb> out;
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) out.push_back(image.Get(x, y));
    }
    return out;
}

double Display(float x, float exposure) {
    return std::pow(1.0 - std::exp(-static_cast<double>(x * exposure)), 1.0 / 2.2);
}

Errors Compare(const std::vector<Rgb>& a, const std::vector<Rgb>& b, float exposure) {
    double num = 0.0, den = 0.0, disp = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        const float av[3] = {a[i].x, a[i].y, a[i].z};
        const float bv[3] = {b[i].x, b[i].y, b[i].z};
        for (int c = 0; c < 3; ++c) {
            const double d = static_cast<double>(av[c]) - static_cast<double>(bv[c]);
            num += d * d;
            den += static_cast<double>(bv[c]) * static_cast<double>(bv[c]);
            const double dd = Display(av[c], exposure) - Display(bv[c], exposure);
            disp += dd * dd;
        }
    }
    Errors e;
    e.rel_rmse = den > 0.0 ? std::sqrt(num / den) : 0.0;
    e.display_rmse = std::sqrt(disp / (3.0 * static_cast<double>(a.size())));
    return e;
}

// The evaluator of tables `t` built with settings `s` for `atm`.
AtmospherePlusEvaluator MakeEval(const AtmosphereParameters& atm, const AplusSettings& s,
                                 const AplusTables& t) {
    AtmospherePlusEvaluator e;
    e.atm = atm;
    e.mapping = s.mapping;
    e.mapping.bottom_radius = atm.bottom_radius;
    e.mapping.height = atm.top_radius - atm.bottom_radius;
    e.scattering = t.scattering.view();
    e.transmittance = t.transmittance.view();
    return e;
}

struct Config {
    std::string name;
    AplusMapping mapping;
};

TEST(AtmospherePlusStudy, DISABLED_ParameterizationTable) {
    AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    atm.solar_irradiance = Vec3d(1.0);  // display error at the views' own exposure
    const std::vector<View> views = StandardViews(atm);
    AtmospherePlusDirectEvaluator direct;
    direct.atm = atm;
    std::vector<std::vector<Rgb>> reference;
    for (const View& v : views) reference.push_back(RenderWith(nullptr, &direct, atm, v));

    std::vector<Config> configs;
    const auto add = [&](const std::string& name, AplusParameterization kind, double pu, double pv,
                         double pw, AplusHorizonAngle angle) {
        Config c;
        c.name = name;
        c.mapping.kind = kind;
        c.mapping.p_u = pu;
        c.mapping.p_v = pv;
        c.mapping.p_w = pw;
        c.mapping.horizon_angle = angle;
        configs.push_back(c);
    };
    const AplusHorizonAngle geo = AplusHorizonAngle::kGeometric;
    add("linear", AplusParameterization::kLinear, 1, 1, 1, geo);
    add("nonlinear", AplusParameterization::kNonlinear, 2, 3, 3, geo);
    add("power(3,3,3)", AplusParameterization::kPower, 3, 3, 3, geo);
    add("power(2,5,2)", AplusParameterization::kPower, 2, 5, 2, geo);
    add("horizon", AplusParameterization::kHorizon, 2, 3, 3, geo);
    add("horizon(seed c_h)", AplusParameterization::kHorizon, 2, 3, 3, AplusHorizonAngle::kSeed);
    const int sizes[][3] = {{16, 64, 16},  {32, 64, 32}, {16, 256, 16}, {32, 128, 32},
                            {32, 256, 32}, {64, 64, 64}, {64, 128, 64}, {64, 256, 64}};

    std::printf("| parameterization | size (W x H x D) | MiB |");
    for (const View& v : views) std::printf(" %s |", v.name.c_str());
    std::printf(" mean |\n|---|---|---|");
    for (size_t i = 0; i <= views.size(); ++i) std::printf("---|");
    std::printf("\n");
    for (const int* size : sizes) {
        for (const Config& c : configs) {
            AplusSettings s;
            s.mapping = c.mapping;
            s.width = size[0];
            s.height = size[1];
            s.depth = size[2];
            s.orders = 1;
            s.transmittance_width = 8;  // transmittance is not measured here
            s.transmittance_height = 8;
            const AplusTables t = AplusPrecompute(atm, s);
            const AtmospherePlusEvaluator e = MakeEval(atm, s, t);
            const double mib =
                static_cast<double>(t.scattering.size() * sizeof(float)) / (1024.0 * 1024.0);
            std::printf("| %s | %dx%dx%d | %.2f |", c.name.c_str(), size[0], size[1], size[2], mib);
            double sum = 0.0, sum_d = 0.0;
            for (size_t v = 0; v < views.size(); ++v) {
                const Errors err = Compare(RenderWith(&e, nullptr, atm, views[v]), reference[v],
                                           views[v].exposure);
                std::printf(" %.3f / %.4f |", err.rel_rmse, err.display_rmse);
                sum += err.rel_rmse;
                sum_d += err.display_rmse;
            }
            std::printf(" %.3f / %.4f |\n", sum / static_cast<double>(views.size()),
                        sum_d / static_cast<double>(views.size()));
            std::fflush(stdout);
        }
    }
}

// The full model (5 orders, the seed's 6 x 12 gather): table error against the
// same numerics in a 64 x 256 x 64 horizon-centric table (stand-in), and the
// effect of the seed's coarse gather against a 24 x 48 gather (same table).
TEST(AtmospherePlusStudy, DISABLED_MultipleScatteringTable) {
    AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    atm.solar_irradiance = Vec3d(1.0);
    const std::vector<View> views = StandardViews(atm);
    const auto settings = [](AplusParameterization kind, int w, int h, int d, int gt, int gp) {
        AplusSettings s;
        s.mapping.kind = kind;
        s.width = w;
        s.height = h;
        s.depth = d;
        s.gather_theta = gt;
        s.gather_phi = gp;
        return s;
    };
    const AplusSettings ref_s = settings(AplusParameterization::kHorizon, 64, 256, 64, 6, 12);
    const AplusTables ref_t = AplusPrecompute(atm, ref_s);
    std::printf("stand-in 64x256x64: order seconds");
    for (double sec : ref_t.order_seconds) std::printf(" %.2f", sec);
    std::printf("\n");
    const AtmospherePlusEvaluator ref_e = MakeEval(atm, ref_s, ref_t);
    std::vector<std::vector<Rgb>> reference;
    for (const View& v : views) reference.push_back(RenderWith(&ref_e, nullptr, atm, v));
    struct Case {
        const char* name;
        AplusSettings s;
    };
    const std::vector<Case> cases = {
        {"horizon 32x64x32", settings(AplusParameterization::kHorizon, 32, 64, 32, 6, 12)},
        {"horizon 32x256x32", settings(AplusParameterization::kHorizon, 32, 256, 32, 6, 12)},
        {"nonlinear 32x256x32", settings(AplusParameterization::kNonlinear, 32, 256, 32, 6, 12)},
        {"horizon 64x64x64", settings(AplusParameterization::kHorizon, 64, 64, 64, 6, 12)},
    };
    std::printf("| table (5 orders) | MiB |");
    for (const View& v : views) std::printf(" %s |", v.name.c_str());
    std::printf(" mean |\n");
    std::vector<std::vector<Rgb>> default_images;
    for (const Case& c : cases) {
        const AplusTables t = AplusPrecompute(atm, c.s);
        const AtmospherePlusEvaluator e = MakeEval(atm, c.s, t);
        std::printf("| %s | %.2f |", c.name,
                    static_cast<double>(t.scattering.size() * sizeof(float)) / 1048576.0);
        double sum = 0.0, sum_d = 0.0;
        for (size_t v = 0; v < views.size(); ++v) {
            std::vector<Rgb> img = RenderWith(&e, nullptr, atm, views[v]);
            const Errors err = Compare(img, reference[v], views[v].exposure);
            std::printf(" %.3f / %.4f |", err.rel_rmse, err.display_rmse);
            sum += err.rel_rmse;
            sum_d += err.display_rmse;
            if (default_images.size() < views.size()) default_images.push_back(img);
        }
        std::printf(" %.3f / %.4f |\n", sum / static_cast<double>(views.size()),
                    sum_d / static_cast<double>(views.size()));
        std::fflush(stdout);
    }
    // Gather resolution: the seed's 6 x 12 against 24 x 48, default table.
    const AplusSettings fine_s = settings(AplusParameterization::kHorizon, 32, 64, 32, 24, 48);
    const AplusTables fine_t = AplusPrecompute(atm, fine_s);
    const AtmospherePlusEvaluator fine_e = MakeEval(atm, fine_s, fine_t);
    std::printf("| gather 6x12 vs 24x48 (horizon 32x64x32) | |");
    for (size_t v = 0; v < views.size(); ++v) {
        const Errors err = Compare(default_images[v], RenderWith(&fine_e, nullptr, atm, views[v]),
                                   views[v].exposure);
        std::printf(" %.3f / %.4f |", err.rel_rmse, err.display_rmse);
    }
    std::printf("\n");
}

}  // namespace
}  // namespace atmos
