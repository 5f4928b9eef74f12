// atmos: the canonical Earth atmosphere and the validation of atmosphere parameters.
//
// Sources: DESIGN.md "Canonical parameters" (the seed thesis's comparison setup,
// Hillaire 2020 demo values); Bruneton 2017 for the layered density
// profile, its ozone layer (two linear layers, 0 below 10 km, 1 at 25 km, 0
// above 40 km) and mu_s_min = cos(102 deg) of its demo; Boody's Atmosphere Plus notes
// sections 1.4-1.8 for the radii, the Rayleigh/Mie coefficients, the scale heights and g = 0.8.
#include <charconv>
#include <cmath>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "physics/density.h"

namespace atmos {

namespace {

// Shortest text that reads back to the same double ("nan", "inf" included).
std::string FormatNumber(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

std::string ChannelName(const std::string& field, int channel) {
    return field + "[" + std::to_string(channel) + "]";
}

[[noreturn]] void FailField(const std::string& field, double value, const std::string& range) {
    if (!std::isfinite(value)) {
        Fail("invalid atmosphere field '", field, "': ", FormatNumber(value),
             " is not a finite number (allowed range ", range, ")");
    }
    Fail("invalid atmosphere field '", field, "': ", FormatNumber(value),
         " is outside the allowed range ", range);
}

// A value in [lo, hi] (closed) or (lo, hi) (open) at either end; NaN and
// infinities always fail.
void CheckRange(const std::string& field, double value, double lo, bool lo_open, double hi,
                bool hi_open, const std::string& range) {
    const bool above_lo = lo_open ? value > lo : value >= lo;
    const bool below_hi = hi_open ? value < hi : value <= hi;
    if (!std::isfinite(value) || !above_lo || !below_hi) {
        FailField(field, value, range);
    }
}

void CheckRgbRange(const std::string& field, const Vec3d& value, double lo, double hi,
                   const std::string& range) {
    for (int c = 0; c < 3; ++c) {
        CheckRange(ChannelName(field, c), value[c], lo, false, hi, false, range);
    }
}

// A scattering or extinction coefficient (1/m at density 1): finite, >= 0, <= 1.
void CheckCoefficient(const std::string& field, const Vec3d& value) {
    CheckRgbRange(field, value, 0.0, 1.0, "[0, 1] (1/m)");
}

void CheckFinite(const std::string& field, double value) {
    if (!std::isfinite(value)) {
        Fail("invalid atmosphere field '", field, "': ", FormatNumber(value),
             " is not a finite number");
    }
}

void CheckProfile(const std::string& field, const DensityProfile& profile) {
    for (int i = 0; i < 2; ++i) {
        const DensityProfileLayer& layer = profile.layers[i];
        const std::string prefix = field + ".layers[" + std::to_string(i) + "].";
        CheckFinite(prefix + "width", layer.width);
        if (layer.width < 0.0) {
            FailField(prefix + "width", layer.width, "[0, +inf) (m)");
        }
        CheckFinite(prefix + "exp_term", layer.exp_term);
        CheckFinite(prefix + "exp_scale", layer.exp_scale);
        CheckFinite(prefix + "linear_term", layer.linear_term);
        CheckFinite(prefix + "constant_term", layer.constant_term);
    }
}

}  // namespace

const char* MiePhaseKindName(MiePhaseKind kind) {
    switch (kind) {
        case MiePhaseKind::kHenyeyGreenstein:
            return "henyey-greenstein";
        case MiePhaseKind::kIsotropic:
            return "isotropic";
        case MiePhaseKind::kTabulated:
            return "tabulated";
        case MiePhaseKind::kCornetteShanks:
        default:
            return "cornette-shanks";
    }
}

// The phase is linear in mu between nodes (atmosphere.h MiePhaseTable), so over
// the interval [a, b] = [mu[i+1], mu[i]] with values va, vb the integrals are
// exact: of the value, (b - a)(va + vb) / 2; of mu times the value,
// (b - a)((2a + b) va + (a + 2b) vb) / 6; times 2 pi for the azimuth.
void FinishMiePhaseTable(MiePhaseTable* t, const std::string& field) {
    const int n = t->count;
    if (n < 2 || n > kMaxMiePhaseNodes) {
        Fail("invalid atmosphere field '", field, "': a tabulated phase function has 2 to ",
             kMaxMiePhaseNodes, " nodes, not ", n);
    }
    for (int i = 0; i < n; ++i) {
        const std::string at = "[" + std::to_string(i) + "]";
        const double angle = t->angle_deg[i];
        const double value = t->value[i];
        if (!std::isfinite(angle) || angle < 0.0 || angle > 180.0) {
            FailField(field + ".angles_deg" + at, angle, "[0, 180] (deg)");
        }
        if (!std::isfinite(value) || !(value > 0.0) || value > 1e30) {
            FailField(field + ".values" + at, value, "(0, 1e+30] (a phase function is positive)");
        }
    }
    if (t->angle_deg[0] != 0.0) {
        Fail("invalid atmosphere field '", field,
             ".angles_deg[0]': ", FormatNumber(t->angle_deg[0]),
             " (the first angle must be 0: the table covers 0 to 180 deg)");
    }
    if (t->angle_deg[n - 1] != 180.0) {
        Fail("invalid atmosphere field '", field, ".angles_deg[", n - 1,
             "]': ", FormatNumber(t->angle_deg[n - 1]),
             " (the last angle must be 180: the table covers 0 to 180 deg)");
    }
    for (int i = 0; i < n; ++i) {
        t->mu[i] = i == 0 ? 1.0 : i == n - 1 ? -1.0 : std::cos(t->angle_deg[i] * (kPi / 180.0));
        if (i > 0 && !(t->angle_deg[i] > t->angle_deg[i - 1] && t->mu[i] < t->mu[i - 1])) {
            Fail("invalid atmosphere field '", field, ".angles_deg[", i,
                 "]': ", FormatNumber(t->angle_deg[i]), " after ",
                 FormatNumber(t->angle_deg[i - 1]),
                 " (the angles must increase strictly, with distinct cosines)");
        }
    }
    double integral = 0.0, first_moment = 0.0;
    double mass[kMaxMiePhaseNodes] = {};
    for (int i = 0; i + 1 < n; ++i) {
        const double a = t->mu[i + 1], b = t->mu[i];
        const double va = t->value[i + 1], vb = t->value[i];
        mass[i] = 2.0 * kPi * (b - a) * 0.5 * (va + vb);
        integral += mass[i];
        first_moment += 2.0 * kPi * (b - a) * ((2.0 * a + b) * va + (a + 2.0 * b) * vb) / 6.0;
    }
    t->scale = 1.0 / integral;
    t->mean_cosine = first_moment / integral;
    double cumulative = 0.0;
    t->cdf[0] = 0.0;
    for (int i = 0; i + 1 < n; ++i) {
        cumulative += mass[i];
        t->cdf[i + 1] = i + 2 == n ? 1.0 : cumulative / integral;
    }
    for (int i = n; i < kMaxMiePhaseNodes; ++i) {
        t->angle_deg[i] = t->value[i] = t->mu[i] = t->cdf[i] = 0.0;
    }
}

// One exponential exp(-h / H): Bruneton's 2017 implementation notes' rayleigh_layer / mie_layer
// (DensityProfileLayer(0, 1, -1/H, 0, 0)) in layers[1]; layers[0] has width 0
// so it never applies.
DensityProfile ExponentialProfile(double scale_height) {
    DensityProfile profile;
    profile.layers[1].exp_term = 1.0;
    profile.layers[1].exp_scale = -1.0 / scale_height;
    return profile;
}

double EffectiveTopRadius(const AtmosphereParameters& a, double column_depth) {
    const double thickness = a.top_radius - a.bottom_radius;
    if (!(thickness > 1.0)) return a.top_radius;
    // Altitudes 0 and a geometric grid from 1 m to the top (ratio ~1.005), the
    // column above each by the trapezoid rule from the top down.
    constexpr int kPoints = 4096;
    const double ratio = std::pow(thickness, 1.0 / (kPoints - 1));
    auto extinction_at = [&](double h) { return MaxComponent(Extinction(a, GetDensities(a, h))); };
    double h_above = thickness;
    double e_above = extinction_at(h_above);
    double column = 0.0;
    for (int k = kPoints - 2; k >= -1; --k) {
        const double h = k >= 0 ? std::pow(ratio, k) : 0.0;
        const double e = extinction_at(h);
        column += 0.5 * (e + e_above) * (h_above - h);
        if (column >= column_depth) return a.bottom_radius + h_above;
        h_above = h;
        e_above = e;
    }
    return a.top_radius;  // (almost) no air at all: keep the shell
}

AtmosphereParameters EarthAtmosphere() {
    AtmosphereParameters a;
    // Boody's Atmosphere Plus notes section 1.4 (Hillaire 2020): R_p and R_a.
    a.bottom_radius = 6360e3;
    a.top_radius = 6460e3;
    // Boody's Atmosphere Plus notes sections 1.6 and 1.8: beta_R^s, H_R = 8 km (no Rayleigh
    // absorption).
    a.rayleigh_scattering = Vec3d(5.802e-6, 13.558e-6, 33.1e-6);
    a.rayleigh_density = ExponentialProfile(8000.0);
    // Hillaire 2020 demo: Mie scattering 3.996e-6, extinction 4.44e-6 (absorption
    // 0.444e-6), H_M = 1.2 km, Cornette-Shanks g = 0.8 (Boody's Atmosphere Plus notes section 1.7).
    a.mie_scattering = Vec3d(3.996e-6);
    a.mie_extinction = Vec3d(4.44e-6);
    a.mie_density = ExponentialProfile(1200.0);
    a.mie_phase_g = 0.8;
    // Ozone: absorption only, Bruneton's 2017 implementation notes' demo tent profile (0 below 10
    // km, 1 at 25 km, 0 above 40 km; GetLayerDensity clamps to [0, 1]).
    a.absorption_extinction = Vec3d(0.650e-6, 1.881e-6, 0.085e-6);
    a.absorption_density.layers[0].width = 25000.0;
    a.absorption_density.layers[0].linear_term = 1.0 / 15000.0;
    a.absorption_density.layers[0].constant_term = -2.0 / 3.0;
    a.absorption_density.layers[1].linear_term = -1.0 / 15000.0;
    a.absorption_density.layers[1].constant_term = 8.0 / 3.0;
    a.ground_albedo = Vec3d(0.0);
    a.sun_angular_radius = 0.004675;
    a.solar_irradiance = Vec3d(1.0);
    // Bruneton's 2017 implementation notes demo: max_sun_zenith_angle = 102 / 180 * pi (the
    // half-precision case).
    a.mu_s_min = std::cos(102.0 / 180.0 * kPi);
    return a;
}

void ValidateAtmosphere(const AtmosphereParameters& a) {
    CheckRange("bottom_radius", a.bottom_radius, 1e3, false, 1e9, false, "[1000, 1e+09] (m)");
    CheckRange("top_radius", a.top_radius, a.bottom_radius, true, 2.0 * a.bottom_radius, false,
               "(bottom_radius, 2 * bottom_radius] = (" + FormatNumber(a.bottom_radius) + ", " +
                   FormatNumber(2.0 * a.bottom_radius) + "] (m)");
    CheckCoefficient("rayleigh_scattering", a.rayleigh_scattering);
    CheckProfile("rayleigh_density", a.rayleigh_density);
    CheckCoefficient("mie_scattering", a.mie_scattering);
    CheckCoefficient("mie_extinction", a.mie_extinction);
    for (int c = 0; c < 3; ++c) {
        if (a.mie_extinction[c] < a.mie_scattering[c]) {
            Fail("invalid atmosphere field '", ChannelName("mie_extinction", c),
                 "': ", FormatNumber(a.mie_extinction[c]), " is less than mie_scattering[", c,
                 "] = ", FormatNumber(a.mie_scattering[c]),
                 " (extinction = scattering + absorption must be >= scattering)");
        }
    }
    CheckProfile("mie_density", a.mie_density);
    CheckRange("mie_phase_g", a.mie_phase_g, -1.0, true, 1.0, true, "(-1, 1)");
    CheckRange("mie_phase_g2", a.mie_phase_g2, -1.0, true, 1.0, true, "(-1, 1)");
    CheckRange("mie_phase_weight2", a.mie_phase_weight2, 0.0, false, 1.0, false, "[0, 1]");
    switch (a.mie_phase_kind) {
        case MiePhaseKind::kCornetteShanks:
        case MiePhaseKind::kHenyeyGreenstein:
        case MiePhaseKind::kIsotropic:
            break;
        case MiePhaseKind::kTabulated: {
            // The derived members must be those of the table (FinishMiePhaseTable).
            MiePhaseTable check = a.mie_phase_table;
            FinishMiePhaseTable(&check, "mie_phase");
            if (check.scale != a.mie_phase_table.scale ||
                check.mean_cosine != a.mie_phase_table.mean_cosine) {
                Fail(
                    "invalid atmosphere field 'mie_phase': the table's normalisation is stale "
                    "(FinishMiePhaseTable was not called after changing it)");
            }
            break;
        }
        default:
            Fail("invalid atmosphere field 'mie_phase': unknown kind ",
                 static_cast<int>(a.mie_phase_kind),
                 " (cornette-shanks, henyey-greenstein, isotropic or tabulated)");
    }
    CheckCoefficient("absorption_extinction", a.absorption_extinction);
    CheckProfile("absorption_density", a.absorption_density);
    CheckRgbRange("ground_albedo", a.ground_albedo, 0.0, 1.0, "[0, 1]");
    CheckRange("sun_angular_radius", a.sun_angular_radius, 0.0, true, 0.5, false, "(0, 0.5] (rad)");
    for (int c = 0; c < 3; ++c) {
        const double value = a.solar_irradiance[c];
        // Bounded so that radiance x irradiance stays finite in float (1e308
        // overflowed to infinity, written as black).
        if (!std::isfinite(value) || value < 0.0 || value > 1e9) {
            FailField(ChannelName("solar_irradiance", c), value, "[0, 1e+09]");
        }
    }
    CheckRange("mu_s_min", a.mu_s_min, -1.0, false, 1.0, false, "[-1, 1]");
}

}  // namespace atmos
