// atmos model `bruneton`: the precomputation (seed 004, every "Precomputation"
// section, and the order loop of Bruneton's model: transmittance, direct
// irradiance, single scattering, then per order n >= 2 the scattering density,
// the indirect irradiance of order n - 1 and the multiple scattering of order n).
// Every stage runs through RunStage (render/stages.h: the CPU's ParallelFor or
// the device) from the stage structs of models/bruneton_stages.h; on the CPU
// backend single and multiple scattering use their row forms (faster on the CPU).
#include <chrono>
#include <cmath>
#include <vector>

#include "atmos/error.h"
#include "base/library_progress.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "models/order_check.h"
#include "render/stages.h"

namespace atmos {

namespace {

using Clock = std::chrono::steady_clock;

// Rows of the 3D scattering table: one (mu, r) pair = (y, z), NU * MU_S texels.
int RowCount(const BrunetonConfig& c) { return c.scattering_mu * c.scattering_r; }

// The row forms in the stage log (render/stages.h), like RunStage's CPU runs.
void LogRows(const char* name, int64_t rows, Clock::time_point start) {
    if (!CurrentStageLog()) return;
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    LogStage({name, rows, "cpu", ms, ms});
}

int64_t TexelCount(const Table& t) {
    return static_cast<int64_t>(t.width()) * t.height() * t.depth();
}

}  // namespace

void ValidateBrunetonConfig(const BrunetonConfig& c) {
    BrunetonModel::OptionRows().Check("bruneton", c);
}

BrunetonLut MakeBrunetonLut(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            const BrunetonTables& tables) {
    BrunetonLut lut(atmosphere, config);
    lut.transmittance_table = tables.transmittance.view();
    lut.irradiance_table = tables.irradiance.view();
    lut.scattering_table = tables.scattering.view();
    lut.single_mie_table = tables.single_mie.view();
    return lut;
}

Table MakeBrunetonDirectionTable() {
    Table t(4 * kBrunetonDirections, 1, 1, 1);
    float* p = t.data();
    const double dtheta = kPi / kBrunetonDensityThetaSamples;
    const double dphi = kPi / kBrunetonDensityThetaSamples;
    for (int l = 0; l < kBrunetonDensityThetaSamples; ++l) {
        const double theta = (l + 0.5) * dtheta;
        for (int m = 0; m < 2 * kBrunetonDensityThetaSamples; ++m) {
            const double phi = (m + 0.5) * dphi;
            const int k = l * 2 * kBrunetonDensityThetaSamples + m;
            p[k] = static_cast<float>(std::cos(phi) * std::sin(theta));
            p[kBrunetonDirections + k] = static_cast<float>(std::sin(phi) * std::sin(theta));
            p[2 * kBrunetonDirections + k] = static_cast<float>(std::cos(theta));
            p[3 * kBrunetonDirections + k] = static_cast<float>(dtheta * dphi * std::sin(theta));
        }
    }
    return t;
}

// Per row (r, mu): the view-ray samples (distance, transmittance from the
// camera, densities) are shared by the row's (mu_s, nu) texels; only the sun's
// transmittance depends on them (BrunetonSingleScatteringStage per texel).
void ComputeBrunetonSingleScatteringRows(const BrunetonLut& lut, Table* rayleigh, Table* mie) {
    const BrunetonConfig& c = lut.cfg;
    const int width = c.scattering_nu * c.scattering_mu_s;
    rayleigh->Resize(width, c.scattering_mu, c.scattering_r, 3);
    mie->Resize(width, c.scattering_mu, c.scattering_r, 3);
    const Clock::time_point start = Clock::now();
    ParallelFor(RowCount(c), 1, [&](int64_t row) {
        const int y = static_cast<int>(row % c.scattering_mu);
        const int z = static_cast<int>(row / c.scattering_mu);
        double r, mu, mu_s, nu;
        bool ground;
        lut.RMuMuSNuFromTexel(0, y, z, &r, &mu, &mu_s, &nu, &ground);
        const int n = c.scattering_samples;
        const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / n;
        std::vector<BrunetonSingleSample> samples(static_cast<size_t>(n) + 1);
        const bool thick = RayHasThickSteps(lut.atm, r, mu, dx, n);
        ThickRayWeights weights(r, mu, dx, n);
        for (int i = 0; i <= n; ++i) {
            Vec3d w;
            if (thick) w = weights.Next(lut.atm, i);
            samples[static_cast<size_t>(i)] =
                BrunetonSingleScatteringSample(lut, r, mu, ground, dx, i, n, thick ? &w : nullptr);
        }
        const Rgb beta_r = Rgb(lut.atm.rayleigh_scattering * dx);
        const Rgb beta_m = Rgb(lut.atm.mie_scattering * dx);
        for (int x = 0; x < width; ++x) {
            double r2, mu2;
            lut.RMuMuSNuFromTexel(x, y, z, &r2, &mu2, &mu_s, &nu, &ground);
            Rgb sum_r, sum_m;
            for (const BrunetonSingleSample& s : samples) {
                BrunetonSingleScatteringAdd(lut, s, r, mu_s, nu, &sum_r, &sum_m);
            }
            rayleigh->Set(x, y, z, BrunetonVec4(sum_r * beta_r));
            mie->Set(x, y, z, BrunetonVec4(sum_m * beta_m));
        }
    });
    LogRows("bruneton single scattering (rows)", RowCount(c), start);
}

// Per row (r, mu): the samples' transmittance from the camera and the (mu, r)
// part of their table coordinates are shared by the row's texels
// (BrunetonMultipleScatteringStage per texel).
void ComputeBrunetonMultipleScatteringRows(const BrunetonLut& lut, const TableView& density,
                                           Table* out) {
    const BrunetonConfig& c = lut.cfg;
    const int width = c.scattering_nu * c.scattering_mu_s;
    out->Resize(width, c.scattering_mu, c.scattering_r, 3);
    const BrunetonFastLookup fast(lut, density);
    const Clock::time_point start = Clock::now();
    ParallelFor(RowCount(c), 1, [&](int64_t row) {
        const int y = static_cast<int>(row % c.scattering_mu);
        const int z = static_cast<int>(row / c.scattering_mu);
        double r, mu, mu_s, nu;
        bool ground;
        lut.RMuMuSNuFromTexel(0, y, z, &r, &mu, &mu_s, &nu, &ground);
        const int n = c.scattering_samples;
        const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / n;
        std::vector<BrunetonMultipleSample> samples(static_cast<size_t>(n) + 1);
        const bool thick = RayHasThickSteps(lut.atm, r, mu, dx, n);
        ThickRayWeights weights(r, mu, dx, n);
        for (int i = 0; i <= n; ++i) {
            Vec3d w;
            if (thick) w = weights.Next(lut.atm, i);
            samples[static_cast<size_t>(i)] = BrunetonMultipleScatteringSample(
                lut, fast, r, mu, ground, dx, i, n, thick ? &w : nullptr);
        }
        // Samples outer, texels inner: the four table rows of one sample stay in
        // the cache while the row's texels read them.
        const size_t w = static_cast<size_t>(width);
        std::vector<double> mu_s_x(w), nu_x(w), tex_x(w);
        std::vector<float> lerp(w);
        std::vector<Rgb> sum(w);
        for (int x = 0; x < width; ++x) {
            double r2, mu2;
            lut.RMuMuSNuFromTexel(x, y, z, &r2, &mu2, &mu_s, &nu, &ground);
            const size_t k = static_cast<size_t>(x);
            mu_s_x[k] = mu_s;
            nu_x[k] = nu;
            BrunetonNuCoordinate(nu, c.scattering_nu, &tex_x[k], &lerp[k]);
        }
        std::vector<double> u_mu_s(w);
        for (const BrunetonMultipleSample& s : samples) {
            // First the mu_s coordinates of all texels (a vectorisable loop)...
            for (size_t k = 0; k < w; ++k) {
                u_mu_s[k] = BrunetonMultipleScatteringUMuS(fast, s, r, mu_s_x[k], nu_x[k]);
            }
            // ...then the lookups.
            for (size_t k = 0; k < w; ++k) {
                sum[k] += BrunetonMultipleScatteringTerm(fast, s, tex_x[k], lerp[k], u_mu_s[k]);
            }
        }
        for (int x = 0; x < width; ++x) {
            out->Set(x, y, z, BrunetonVec4(sum[static_cast<size_t>(x)]));
        }
    });
    LogRows("bruneton multiple scattering (rows)", RowCount(c), start);
}

void PrecomputeBruneton(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                        BrunetonTables* tables, const BrunetonOrderCallback& on_order) {
    PrecomputeBrunetonWith(atmosphere, config, IsDeviceBackend(CurrentBackend()), tables, on_order);
}

void PrecomputeBrunetonWith(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            bool texel_stages, BrunetonTables* tables,
                            const BrunetonOrderCallback& on_order) {
    ValidateBrunetonConfig(config);
    BrunetonLut lut(atmosphere, config);
    const BrunetonLut mappings = BrunetonMappingsOnly(lut);
    const int width = config.scattering_nu * config.scattering_mu_s;
    // A progress bar (CLI, over a second): one step for order 1, four per
    // further order (incident radiance, density, irradiance, multiple scattering).
    Progress progress("bruneton precompute", 1 + 4 * static_cast<int64_t>(config.orders - 1),
                      LibraryProgressEnabled());
    // On a device backend all tables stay on the device between the stages;
    // the host gets the final tables, and the tables on_order reads, by Download.
    StageSession session;
    const auto download = [&](Table* delta_density) {
        session.Download(&tables->transmittance);
        session.Download(&tables->irradiance);
        session.Download(&tables->scattering);
        session.Download(&tables->single_mie);
        if (delta_density) session.Download(delta_density);
    };

    tables->transmittance.Resize(config.transmittance_width, config.transmittance_height, 1, 3);
    RunStage("bruneton transmittance", TexelCount(tables->transmittance),
             config.transmittance_width,
             BrunetonTransmittanceStage{mappings, tables->transmittance.out()});
    lut.transmittance_table = tables->transmittance.view();

    Table delta_irradiance(config.irradiance_width, config.irradiance_height, 1, 3);
    RunStage("bruneton direct irradiance", TexelCount(delta_irradiance), config.irradiance_width,
             BrunetonDirectIrradianceStage{lut, delta_irradiance.out()});
    // The irradiance table holds the indirect irradiance only (the direct one is
    // computed at render time from the transmittance, seed 004).
    tables->irradiance.Resize(config.irradiance_width, config.irradiance_height, 1, 3);

    Table delta_rayleigh, delta_mie;
    if (texel_stages) {
        delta_rayleigh.Resize(width, config.scattering_mu, config.scattering_r, 3);
        delta_mie.Resize(width, config.scattering_mu, config.scattering_r, 3);
        RunStage("bruneton single scattering", TexelCount(delta_rayleigh), width,
                 BrunetonSingleScatteringStage{lut, delta_rayleigh.out(), delta_mie.out()});
    } else {
        ComputeBrunetonSingleScatteringRows(lut, &delta_rayleigh, &delta_mie);
    }
    tables->scattering.Resize(width, config.scattering_mu, config.scattering_r,
                              config.combined_mie ? 4 : 3);
    if (config.combined_mie) {
        tables->single_mie = Table();
    } else {
        tables->single_mie.Resize(width, config.scattering_mu, config.scattering_r, 3);
    }
    RunStage("bruneton combine", TexelCount(delta_rayleigh), width,
             BrunetonCombineStage{delta_rayleigh.view(), delta_mie.view(), tables->scattering.out(),
                                  config.combined_mie ? TableOut() : tables->single_mie.out()});
    progress.Add(1);
    if (on_order) {
        download(nullptr);
        on_order(1, *tables, nullptr);
    }

    const Table directions = MakeBrunetonDirectionTable();
    Table incident, delta_multiple, delta_density;
    // Each order's multiple scattering is summed: orders that stop decreasing
    // are reported (models/order_check.h; orders >= 2 share their units).
    ScatteringOrders sums;
    for (int order = 2; order <= config.orders; ++order) {
        // 1. Incident radiance per (r, mu_s, direction); 2. per texel, its
        // phase-weighted sums in the sun's frame.
        incident.Resize(3 * kBrunetonDirections, config.scattering_mu_s, config.scattering_r, 1);
        BrunetonIncidentStage inc;
        inc.lut = lut;
        inc.single_rayleigh = delta_rayleigh.view();
        inc.single_mie = delta_mie.view();
        inc.multiple = delta_multiple.view();
        inc.ground_irradiance = delta_irradiance.view();
        inc.directions = directions.view();
        inc.order = order;
        inc.incident = incident.out();
        if (order == 2) {
            inc.multiple = TableView();
        } else {
            inc.single_rayleigh = TableView();
            inc.single_mie = TableView();
        }
        if (MaxComponent(atmosphere.ground_albedo) <= 0.0) inc.ground_irradiance = TableView();
        RunStage("bruneton incident radiance",
                 static_cast<int64_t>(kBrunetonDirections) * config.scattering_mu_s *
                     config.scattering_r,
                 kBrunetonDirections, inc);
        progress.Add(1);
        delta_density.Resize(width, config.scattering_mu, config.scattering_r, 3);
        RunStage("bruneton scattering density", TexelCount(delta_density), width,
                 BrunetonDensityStage{mappings, incident.view(), directions.view(),
                                      delta_density.out()});
        progress.Add(1);

        BrunetonIndirectIrradianceStage irr;
        irr.lut = mappings;
        irr.order = order - 1;
        if (irr.order == 1) {
            irr.single_rayleigh = delta_rayleigh.view();
            irr.single_mie = delta_mie.view();
        } else {
            irr.multiple = delta_multiple.view();
        }
        irr.out = delta_irradiance.out();
        RunStage("bruneton indirect irradiance", TexelCount(delta_irradiance), 4, irr);
        RunStage("bruneton add irradiance", TexelCount(delta_irradiance), config.irradiance_width,
                 BrunetonAddStage{delta_irradiance.view(), tables->irradiance.out(true)});
        progress.Add(1);

        if (texel_stages) {
            delta_multiple.Resize(width, config.scattering_mu, config.scattering_r, 3);
            RunStage(
                "bruneton multiple scattering", TexelCount(delta_multiple), width,
                BrunetonMultipleScatteringStage{lut, delta_density.view(), delta_multiple.out()});
        } else {
            ComputeBrunetonMultipleScatteringRows(lut, delta_density.view(), &delta_multiple);
        }
        progress.Add(1);
        session.Download(&delta_multiple);
        sums.Add(order, TableSum(delta_multiple));
        // Accumulate, divided by the Rayleigh phase function (the renderer
        // multiplies the whole table by it; seed 004 "Rendering").
        RunStage(
            "bruneton accumulate", TexelCount(delta_multiple), width,
            BrunetonAccumulateStage{mappings, delta_multiple.view(), tables->scattering.out(true)});
        if (on_order) {
            download(&delta_density);
            on_order(order, *tables, &delta_density);
        }
    }
    download(nullptr);
    sums.WarnIfDiverging("bruneton", 3);
}

}  // namespace atmos
