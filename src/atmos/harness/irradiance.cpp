// atmos: horizontal irradiance by quadrature of a model's sky (harness/irradiance.h).
#include "harness/irradiance.h"

#include <cstdio>

#include <cmath>
#include <vector>

#include "atmos/error.h"

namespace atmos {

namespace {

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n; Abramowitz &
// Stegun 25.4.29).
void GaussLegendre(int n, std::vector<double>* x, std::vector<double>* w) {
    x->assign(n, 0.0);
    w->assign(n, 0.0);
    for (int i = 0; i < n; ++i) {
        double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
        double dp = 1.0;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            const double dz = p1 / dp;
            z -= dz;
            if (std::fabs(dz) < 1e-15) break;
        }
        (*x)[i] = z;
        (*w)[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
}

Vec3d Diffuse(const Model& model, double altitude_m, double mu_s, int n_mu, int n_az) {
    std::vector<double> x, w;
    GaussLegendre(n_mu, &x, &w);
    std::vector<SampleQuery> queries;
    queries.reserve(static_cast<size_t>(n_mu) * n_az);
    for (int i = 0; i < n_mu; ++i) {
        for (int j = 0; j < n_az; ++j) {
            SampleQuery q;
            q.altitude_m = altitude_m;
            q.mu = 0.5 * (x[i] + 1.0);  // [0, 1]
            q.mu_s = mu_s;
            q.azimuth_deg = 360.0 * (j + 0.5) / n_az;
            queries.push_back(q);
        }
    }
    const std::vector<SampleAnswer> a = model.Sample(queries);
    Vec3d sum(0.0);
    for (int i = 0; i < n_mu; ++i) {
        const double mu = 0.5 * (x[i] + 1.0);
        const double weight = 0.5 * w[i] * mu * (2.0 * kPi / n_az);
        for (int j = 0; j < n_az; ++j)
            sum += Vec3d(a[static_cast<size_t>(i) * n_az + j].radiance) * weight;
    }
    return sum;
}

}  // namespace

HorizontalIrradiance ComputeHorizontalIrradiance(const Model& model,
                                                 const AtmosphereParameters& atmosphere,
                                                 double altitude_m, double sun_elevation_deg,
                                                 double tolerance) {
    if (!std::isfinite(altitude_m) || altitude_m < 0.0) {
        Fail("irradiance: altitude must be >= 0 m, got ", altitude_m);
    }
    if (!(sun_elevation_deg >= -90.0 && sun_elevation_deg <= 90.0)) {
        Fail("irradiance: sun elevation must be in [-90, 90] degrees, got ", sun_elevation_deg);
    }
    const double mu_s = std::sin(Radians(sun_elevation_deg));
    const Vec3d e_sun(atmosphere.solar_irradiance);
    HorizontalIrradiance out;
    // The sun: its transmittance from the observer (0 behind the planet).
    SampleQuery sun;
    sun.altitude_m = altitude_m;
    sun.mu = mu_s;
    sun.mu_s = mu_s;
    const SampleAnswer to_sun = model.Sample({sun})[0];
    out.direct = Vec3d(to_sun.transmittance) * e_sun * std::max(mu_s, 0.0);
    int n_mu = 16, n_az = 64;
    Vec3d coarse = Diffuse(model, altitude_m, mu_s, n_mu, n_az);
    Vec3d fine = coarse;
    for (;;) {
        n_mu *= 2;
        n_az *= 2;
        fine = Diffuse(model, altitude_m, mu_s, n_mu, n_az);
        double change = 0.0, scale = 0.0;
        for (int c = 0; c < 3; ++c) {
            change = std::max(change, std::fabs(fine[c] - coarse[c]));
            scale = std::max(scale, std::fabs(fine[c]));
        }
        if (change <= tolerance * scale || n_mu >= 256) break;
        coarse = fine;
    }
    out.diffuse = fine * e_sun;
    out.diffuse_coarse = coarse * e_sun;
    out.mu_nodes = n_mu;
    out.azimuth_nodes = n_az;
    Rgb table;
    if (model.TableSkyIrradiance(altitude_m, mu_s, &table)) {
        out.has_table = true;
        out.diffuse_table = Vec3d(table) * e_sun;
    }
    return out;
}

std::string HorizontalIrradianceCsv(const HorizontalIrradiance& e) {
    std::string csv = "quantity,r,g,b\n";
    auto row = [&csv](const char* name, const Vec3d& v) {
        char line[160];
        std::snprintf(line, sizeof line, "%s,%.9g,%.9g,%.9g\n", name, v.x, v.y, v.z);
        csv += line;
    };
    row("direct", e.direct);
    row("diffuse", e.diffuse);
    if (e.has_table) row("diffuse_table", e.diffuse_table);
    return csv;
}

}  // namespace atmos
