// The reference's baseline estimator (`estimator=thesis`): the thesis's
// (Leenman's 2025 thesis section 4) one random channel per path, delta tracking, uniform
// directions; kept to measure the others against.
#pragma once

#include "models/reference_tracking.h"

namespace atmos {

struct ReferenceBaseline : ReferenceTracking {
    // Thesis baseline: is the sun visible from p (delta tracking in channel c)?
    ATMOS_HD bool SunVisibleDelta(Vec3d p, const Vec3d& dir, int shell, int c, Rng& rng) const {
        const double r = Length(p);
        if (RayIntersectsGround(r, ClampCosine(Dot(p, dir) / r), atm.bottom_radius)) return false;
        for (int guard = 0; guard < 1000000; ++guard) {
            const Step step = Track(&p, dir, &shell, rng);
            if (step == Step::kEscaped) return true;
            if (step == Step::kGround) return false;
            const Vec3d sigma_t = Extinction(atm, GetDensities(atm, Length(p) - atm.bottom_radius));
            if (rng.Uniform() * shells.majorant[shell] < sigma_t[c]) return false;
        }
        return false;
    }

    // Thesis baseline path (see `spectral`): adds to one random channel, times 3.
    ATMOS_HD void TracePathThesis(Vec3d p, Vec3d dir, int shell, const Vec3d& sun, Rng& rng,
                                  Vec3d* sky, Vec3d* ground) const {
        const int c = Min(static_cast<int>(rng.Uniform() * 3.0), 2);
        double w = 3.0;
        double radiance = 0.0;
        int order = 0;
        bool first_on_ground = false;
        for (int guard = 0; guard < 1000000; ++guard) {
            const Step step = Track(&p, dir, &shell, rng);
            if (step == Step::kEscaped) break;
            if (step == Step::kGround) {
                if (order == 0) first_on_ground = true;
                ++order;
                if ((max_order > 0 && order > max_order) || atm.ground_albedo[c] <= 0.0) break;
                const Vec3d n = Normalize(p);
                const double cos_sun = Dot(n, sun);
                if (cos_sun > 0.0 && SunVisibleDelta(p, sun, 0, c, rng)) {
                    radiance += w * atm.ground_albedo[c] * cos_sun / kPi;
                }
                dir = MakeDirection(n, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                w *= atm.ground_albedo[c];
            } else {
                const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
                const double sigma_r = atm.rayleigh_scattering[c] * d.rayleigh;
                const double sigma_m = atm.mie_scattering[c] * d.mie;
                const double sigma_t = Extinction(atm, d)[c];
                const double xi = rng.Uniform() * shells.majorant[shell];
                if (xi >= sigma_t) continue;         // null collision
                if (xi >= sigma_r + sigma_m) break;  // absorbed
                const bool rayleigh = xi < sigma_r;
                ++order;
                if (max_order > 0 && order > max_order) break;
                const double nu = Dot(dir, sun);
                if (SunVisibleDelta(p, sun, shell, c, rng)) {
                    radiance += w * (rayleigh ? RayleighPhase(nu) : MiePhase(atm, nu));
                }
                const Vec3d next = MakeDirection(dir, 1.0 - 2.0 * rng.Uniform(), rng.Uniform());
                const double mu = Dot(next, dir);
                w *= 4.0 * kPi * (rayleigh ? RayleighPhase(mu) : MiePhase(atm, mu));
                dir = next;
            }
            if (order >= 3) {
                const double q = Min(0.95, w);
                if (rng.Uniform() >= q) break;
                w /= q;
            }
        }
        Vec3d add;
        add[c] = radiance;
        if (first_on_ground) {
            *ground += add;
        } else {
            *sky += add;
        }
    }
};

}  // namespace atmos
