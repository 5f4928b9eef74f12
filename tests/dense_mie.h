// Issue 18 item 4's dense Mie layer, shared by the tests that use it.
#pragma once

#include "atmos/atmosphere.h"

namespace atmos {

// 0.01 /m extinction, albedo 0.3, g 0.9, earth's 1.2 km scale height
// (vertical optical depth 12); no Rayleigh, no ozone, a black ground.
inline AtmosphereParameters DenseMiePlanet() {
    AtmosphereParameters a = EarthAtmosphere();
    a.rayleigh_scattering = Vec3d(0.0);
    a.mie_extinction = Vec3d(0.01);
    a.mie_scattering = Vec3d(0.003);
    a.mie_phase_g = 0.9;
    a.absorption_extinction = Vec3d(0.0);
    a.ground_albedo = Vec3d(0.0);
    ValidateAtmosphere(a);
    return a;
}

}  // namespace atmos
