// atmos: numerical optical depth and transmittance.
//
// Optical depth tau = integral of the extinction coefficient along a ray
// (Leenman's 2025 thesis Eq. 1 and 4; Bruneton's 2017 implementation notes
// ComputeOpticalLengthToTopAtmosphereBoundary). These functions integrate it numerically: the
// reference for the closed forms and approximations of the other models.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "physics/density.h"
#include "physics/geometry.h"

namespace atmos {

// Optical length (metres at density 1) of `profile` along the segment
// p(t) = origin + t dir, t in [0, length], by the composite trapezoidal rule
// with `samples` intervals (Bruneton's 2017 implementation notes uses 500).
ATMOS_HD inline double OpticalLength(const AtmosphereParameters& atm, const DensityProfile& profile,
                                     const Vec3d& origin, const Vec3d& dir, double length,
                                     int samples) {
    const double dx = length / samples;
    double sum = 0.0;
    for (int i = 0; i <= samples; ++i) {
        const double t = i * dx;
        const double altitude = Length(origin + dir * t) - atm.bottom_radius;
        const double w = (i == 0 || i == samples) ? 0.5 : 1.0;
        sum += w * GetProfileDensity(profile, altitude);
    }
    return sum * dx;
}

// Optical depth (dimensionless, per channel) of all constituents along the
// segment, trapezoidal rule with `samples` intervals.
ATMOS_HD inline Vec3d OpticalDepth(const AtmosphereParameters& atm, const Vec3d& origin,
                                   const Vec3d& dir, double length, int samples) {
    const double dx = length / samples;
    Vec3d sum;
    for (int i = 0; i <= samples; ++i) {
        const double t = i * dx;
        const double altitude = Length(origin + dir * t) - atm.bottom_radius;
        const double w = (i == 0 || i == samples) ? 0.5 : 1.0;
        sum += Extinction(atm, GetDensities(atm, altitude)) * w;
    }
    return sum * dx;
}

// Optical depth from (r, mu) to the top of the atmosphere (Bruneton's 2017 implementation notes'
// parameterisation), for a ray that does not hit the ground.
ATMOS_HD inline Vec3d OpticalDepthToTopAtmosphereBoundary(const AtmosphereParameters& atm, double r,
                                                          double mu, int samples) {
    const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
    const Vec3d origin(0.0, 0.0, r);
    const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
    return OpticalDepth(atm, origin, dir, d, samples);
}

ATMOS_HD inline Vec3d TransmittanceFromOpticalDepth(const Vec3d& tau) { return Exp(-tau); }

}  // namespace atmos
