// atmos CLI: `atmos sample --wavelengths ...` (issue 17), kept apart from
// cmd_sample.cpp's RGB reading and printing.
//
// Columns: altitude_m, mu, mu_s, azimuth_deg, one L_<nm> per wavelength (spectral
// radiance: the atmosphere's solar spectrum times the radiance per unit
// irradiance, no sun disc, no ground; W m^-2 sr^-1 nm^-1 for a solar spectrum in
// W m^-2 nm^-1), then X, Y, Z: 683 lm/W times the CIE 1931 integral over the given
// bins (cd m^-2 for those units).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "cli_common.h"
#include "harness/spectral_run.h"
#include "sample_spectral.h"

namespace atmos::cli {

int SampleSpectralCsv(const CommonOptions& common, const MonteCarloSettings& monte_carlo,
                      const std::string& wavelengths, const std::vector<SampleQuery>& queries,
                      BatchSeeds seeds) {
    if (!common.load.empty()) Fail("--load cannot be combined with --wavelengths");
    const std::vector<double> nm = ParseWavelengths(wavelengths);
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(common.atmosphere, common.sets);
    const std::vector<double> values = SampleSpectral(
        GivenModel(common), atmosphere, nm, queries, monte_carlo,
        [&](const AtmosphereParameters& a, Model* model) { PrepareModel(common, a, model); },
        seeds);
    const std::vector<double> weights = WavelengthWeights(nm);
    std::string header = "altitude_m,mu,mu_s,azimuth_deg";
    for (double l : nm) header += ",L_" + WavelengthLabel(l);
    std::printf("%s,X,Y,Z\n", header.c_str());
    const size_t n = nm.size();
    for (size_t q = 0; q < queries.size(); ++q) {
        std::printf("%.17g,%.17g,%.17g,%.17g", queries[q].altitude_m, queries[q].mu,
                    queries[q].mu_s, queries[q].azimuth_deg);
        for (size_t i = 0; i < n; ++i) std::printf(",%.9g", values[q * n + i]);
        const Vec3d xyz = SpectrumToXyz(nm, weights, values.data() + q * n);
        std::printf(",%.9g,%.9g,%.9g\n", kMaxLuminousEfficacy * xyz.x, kMaxLuminousEfficacy * xyz.y,
                    kMaxLuminousEfficacy * xyz.z);
    }
    return 0;
}

}  // namespace atmos::cli
