// atmos: density profiles of the atmosphere's constituents.
//
// Source: Bruneton 2017, functions.glsl "GetLayerDensity",
// "GetProfileDensity". Densities are dimensionless multipliers of the
// coefficients in AtmosphereParameters, clamped to [0, 1] as in the seed.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"

namespace atmos {

ATMOS_HD inline double GetLayerDensity(const DensityProfileLayer& layer, double altitude) {
    // A layer without its exponential term (exp_term 0) has none: 0 x exp(h)
    // would be 0 x inf = NaN where exp(h) overflows (issue 18 item 3).
    const double e = layer.exp_term != 0.0 ? layer.exp_term * Exp(layer.exp_scale * altitude) : 0.0;
    const double density = e + layer.linear_term * altitude + layer.constant_term;
    return Clamp(density, 0.0, 1.0);
}

ATMOS_HD inline double GetProfileDensity(const DensityProfile& profile, double altitude) {
    return altitude < profile.layers[0].width ? GetLayerDensity(profile.layers[0], altitude)
                                              : GetLayerDensity(profile.layers[1], altitude);
}

// The three densities at one altitude.
struct Densities {
    double rayleigh, mie, absorption;
};

ATMOS_HD inline Densities GetDensities(const AtmosphereParameters& atm, double altitude) {
    return {GetProfileDensity(atm.rayleigh_density, altitude),
            GetProfileDensity(atm.mie_density, altitude),
            GetProfileDensity(atm.absorption_density, altitude)};
}

// Extinction coefficient (1/m, per channel) at the given densities: Rayleigh
// scattering + Mie extinction + absorption (Bruneton's 2017 implementation notes,
// ComputeTransmittance...).
ATMOS_HD inline Vec3d Extinction(const AtmosphereParameters& atm, const Densities& d) {
    return atm.rayleigh_scattering * d.rayleigh + atm.mie_extinction * d.mie +
           atm.absorption_extinction * d.absorption;
}

}  // namespace atmos
