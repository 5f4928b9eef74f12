// atmos studies: the writers of a spectral sample run (`atmos sample
// --wavelengths`, harness/spectral_run.h SampleSpectral): per query the
// spectral radiance at each wavelength, then X, Y, Z.
//
// Columns: altitude_m, mu, mu_s, azimuth_deg, one L_<nm> per wavelength (spectral
// radiance: the atmosphere's solar spectrum times the radiance per unit
// irradiance, no sun disc, no ground; W m^-2 sr^-1 nm^-1 for a solar spectrum in
// W m^-2 nm^-1), then X, Y, Z: 683 lm/W times the CIE 1931 integral over the given
// bins (cd m^-2 for those units).
#pragma once

#include <string>
#include <vector>

#include "atmos/model.h"

namespace atmos {

// The CSV (header, then one row per query; inputs as %.17g, outputs as %.9g);
// `values` is [query * nm.size() + i].
std::string SpectralSampleCsv(const std::vector<double>& nm,
                              const std::vector<SampleQuery>& queries,
                              const std::vector<double>& values);
// The same outputs as a float32 array of shape (queries, wavelengths + 3): the
// L_<nm> values then X, Y, Z per row.
std::vector<float> SpectralSampleArray(const std::vector<double>& nm, size_t queries,
                                       const std::vector<double>& values);

}  // namespace atmos
