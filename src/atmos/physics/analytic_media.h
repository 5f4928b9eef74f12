// atmos: the atmosphere as the analytic models see it: two exponential media
// (Rayleigh, Mie) with one scale height each, and ozone as a constant-density
// shell (Leenman's 2025 thesis section 10.5, Eq. 59).
//
// Mapping from the canonical parameters (DESIGN.md): each layered density
// profile's upper layer exp_term * exp(-h / H) gives the scale height H
// (ProfileScaleHeight) and a density multiplier (exp_term, 1 for every preset);
// a profile that is not a decaying exponential contributes nothing. The ozone
// shell keeps the absorption profile's column and centroid (MakeOzoneShell).
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "physics/analytic_optical_depth.h"
#include "physics/phase.h"

namespace atmos {

struct AnalyticMedia {
    double bottom = 6360e3;  // m
    double top = 6460e3;     // m
    double rayleigh_H = 8000.0;
    double mie_H = 1200.0;
    Vec3d rayleigh_scattering;  // 1/m at the ground (times the profile's exp_term)
    Vec3d mie_scattering;
    Vec3d mie_extinction;
    Vec3d ozone_absorption;  // 1/m inside the shell
    OzoneShell ozone;
    double mie_g = 0.8;
    double mie_g2 = 0.0;  // the second lobe (MiePhase)
    double mie_w2 = 0.0;  // its weight
    MiePhaseKind mie_kind = MiePhaseKind::kCornetteShanks;
    MiePhaseTable mie_table;  // a tabulated phase function (mie_kind kTabulated)
    Vec3d ground_albedo;

    ATMOS_HD Vec3d Extinction(double l_rayleigh, double l_mie, double l_ozone) const {
        return rayleigh_scattering * l_rayleigh + mie_extinction * l_mie +
               ozone_absorption * l_ozone;
    }
    // The atmosphere's Mie phase (any kind: phase.h MiePhase).
    ATMOS_HD double MiePhaseAt(double nu) const {
        return MiePhase(mie_kind, mie_g, mie_g2, mie_w2, mie_table, nu);
    }
};

AnalyticMedia MakeAnalyticMedia(const AtmosphereParameters& atm);

// Optical lengths (m) of the three media along one ray or segment.
struct MediaLengths {
    double rayleigh = 0.0, mie = 0.0, ozone = 0.0;
};

// exp(-a) (1 - exp(-(b - a))) / (b - a): the integral over u in [0, 1] of
// exp(-(a + u (b - a))), the segment integral of Leenman's 2025 thesis Eq. 46-47 / 54-55 with
// the exponent varying linearly from a to b. Stable when b ~ a (limit exp(-a)).
ATMOS_HD inline double LinearExpIntegral(double a, double b) {
    const double d = b - a;
    if (Abs(d) < 1e-6) return Exp(-a) * (1.0 - 0.5 * d);
    return (Exp(-a) - Exp(-b)) / d;
}

ATMOS_HD inline Vec3d LinearExpIntegral(const Vec3d& a, const Vec3d& b) {
    return {LinearExpIntegral(a.x, b.x), LinearExpIntegral(a.y, b.y), LinearExpIntegral(a.z, b.z)};
}

}  // namespace atmos
