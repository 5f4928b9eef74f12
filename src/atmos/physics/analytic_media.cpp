#include "physics/analytic_media.h"

#include "physics/density.h"

namespace atmos {

OzoneShell MakeOzoneShell(const AtmosphereParameters& atm) {
    // Column and centroid of the absorption profile by the midpoint rule
    // (10 m steps over the atmosphere's thickness).
    const double thickness = atm.top_radius - atm.bottom_radius;
    const int n = static_cast<int>(thickness / 10.0) + 1;
    const double dh = thickness / n;
    double column = 0.0, moment = 0.0;
    for (int i = 0; i < n; ++i) {
        const double h = (i + 0.5) * dh;
        const double rho = GetProfileDensity(atm.absorption_density, h);
        column += rho * dh;
        moment += rho * h * dh;
    }
    OzoneShell shell;
    if (column <= 0.0 || MaxComponent(atm.absorption_extinction) <= 0.0) return shell;
    const double centroid = moment / column;
    shell.r_inner = atm.bottom_radius + Max(0.0, centroid - 0.5 * column);
    shell.r_outer = shell.r_inner + column;
    return shell;
}

AnalyticMedia MakeAnalyticMedia(const AtmosphereParameters& atm) {
    AnalyticMedia m;
    m.bottom = atm.bottom_radius;
    m.top = atm.top_radius;
    const double thickness = atm.top_radius - atm.bottom_radius;
    m.rayleigh_H = ProfileScaleHeight(atm.rayleigh_density, thickness);
    m.mie_H = ProfileScaleHeight(atm.mie_density, thickness);
    const double kr = ProfileExpTerm(atm.rayleigh_density);
    const double km = ProfileExpTerm(atm.mie_density);
    m.rayleigh_scattering = atm.rayleigh_scattering * kr;
    m.mie_scattering = atm.mie_scattering * km;
    m.mie_extinction = atm.mie_extinction * km;
    m.ozone = MakeOzoneShell(atm);
    m.ozone_absorption = m.ozone.Empty() ? Vec3d(0.0) : atm.absorption_extinction;
    m.mie_g = atm.mie_phase_g;
    m.mie_g2 = atm.mie_phase_g2;
    m.mie_w2 = atm.mie_phase_weight2;
    m.mie_kind = atm.mie_phase_kind;
    m.mie_table = atm.mie_phase_table;
    m.ground_albedo = atm.ground_albedo;
    return m;
}

}  // namespace atmos
