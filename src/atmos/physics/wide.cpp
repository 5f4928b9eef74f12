// atmos: the coefficients of a wide channel batch (physics/wide.h).
#include "physics/wide.h"

#include <string>

#include "atmos/error.h"

namespace atmos {

namespace {

// `a` with the per-wavelength coefficients of `from` (what a spectral
// atmosphere's AtWavelengths sets), so that two batches compare on the rest.
AtmosphereParameters WithCoefficientsOf(AtmosphereParameters a, const AtmosphereParameters& from) {
    a.rayleigh_scattering = from.rayleigh_scattering;
    a.mie_scattering = from.mie_scattering;
    a.mie_extinction = from.mie_extinction;
    a.absorption_extinction = from.absorption_extinction;
    a.ground_albedo = from.ground_albedo;
    a.solar_irradiance = from.solar_irradiance;
    return a;
}

}  // namespace

WideCoefficients MakeWideCoefficients(const std::vector<AtmosphereParameters>& batches) {
    if (batches.empty()) Fail("wide channel batches: no batch given");
    if (batches.size() * 3 > static_cast<size_t>(kMaxWideChannels)) {
        Fail("wide channel batches: ", batches.size(), " batches of three channels, at most ",
             kMaxWideChannels / 3);
    }
    const std::string first = AtmosphereToJson(batches[0]);
    WideCoefficients w;
    w.channels = static_cast<int>(batches.size()) * 3;
    for (size_t b = 0; b < batches.size(); ++b) {
        const AtmosphereParameters& a = batches[b];
        if (b > 0 && AtmosphereToJson(WithCoefficientsOf(a, batches[0])) != first) {
            Fail("wide channel batches: batch ", b,
                 " differs from batch 0 in a field other than the per-wavelength coefficients "
                 "(rayleigh_scattering, mie_scattering, mie_extinction, absorption_extinction, "
                 "ground_albedo, solar_irradiance)");
        }
        for (int c = 0; c < 3; ++c) {
            const size_t i = 3 * b + static_cast<size_t>(c);
            w.rayleigh_scattering[i] = a.rayleigh_scattering[c];
            w.mie_scattering[i] = a.mie_scattering[c];
            w.mie_extinction[i] = a.mie_extinction[c];
            w.absorption_extinction[i] = a.absorption_extinction[c];
            w.ground_albedo[i] = a.ground_albedo[c];
            w.solar_irradiance[i] = a.solar_irradiance[c];
        }
    }
    return w;
}

}  // namespace atmos
