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
#include "io/image_formats.h"
#include "sample_spectral.h"

namespace atmos::cli {

int SampleSpectralCsv(const CommonOptions& common, const MonteCarloSettings& monte_carlo,
                      const std::string& wavelengths, const std::vector<SampleQuery>& queries,
                      BatchSeeds seeds, const std::string& output, bool npy) {
    if (!common.load.empty()) Fail("--load cannot be combined with --wavelengths");
    const std::vector<double> nm = ParseWavelengths(wavelengths);
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(common.atmosphere, common.sets);
    const std::vector<double> values = SampleSpectral(
        GivenModel(common), atmosphere, nm, queries, monte_carlo,
        [&](const AtmosphereParameters& a, Model* model) { PrepareModel(common, a, model); },
        seeds);
    const std::vector<double> weights = WavelengthWeights(nm);
    const size_t n = nm.size();
    if (npy) {
        std::vector<float> array(queries.size() * (n + 3));
        for (size_t q = 0; q < queries.size(); ++q) {
            float* row = array.data() + q * (n + 3);
            for (size_t i = 0; i < n; ++i) row[i] = static_cast<float>(values[q * n + i]);
            const Vec3d xyz = SpectrumToXyz(nm, weights, values.data() + q * n);
            for (int k = 0; k < 3; ++k) {
                row[n + static_cast<size_t>(k)] = static_cast<float>(kMaxLuminousEfficacy * xyz[k]);
            }
        }
        detail::WriteNpyArray(output, {queries.size(), n + 3}, array.data());
        return 0;
    }
    std::FILE* f = stdout;
    if (!output.empty() && output != "-") {
        f = std::fopen(output.c_str(), "wb");
        if (f == nullptr) Fail("cannot write '", output, "'");
    }
    std::string header = "altitude_m,mu,mu_s,azimuth_deg";
    for (double l : nm) header += ",L_" + WavelengthLabel(l);
    std::fprintf(f, "%s,X,Y,Z\n", header.c_str());
    for (size_t q = 0; q < queries.size(); ++q) {
        std::fprintf(f, "%.17g,%.17g,%.17g,%.17g", queries[q].altitude_m, queries[q].mu,
                     queries[q].mu_s, queries[q].azimuth_deg);
        for (size_t i = 0; i < n; ++i) std::fprintf(f, ",%.9g", values[q * n + i]);
        const Vec3d xyz = SpectrumToXyz(nm, weights, values.data() + q * n);
        std::fprintf(f, ",%.9g,%.9g,%.9g\n", kMaxLuminousEfficacy * xyz.x,
                     kMaxLuminousEfficacy * xyz.y, kMaxLuminousEfficacy * xyz.z);
    }
    const bool ok = std::ferror(f) == 0;
    if (f != stdout) {
        if (std::fclose(f) != 0 || !ok) Fail("cannot write '", output, "'");
    } else if (!ok || std::fflush(f) != 0) {
        Fail("cannot write the spectral columns to stdout");
    }
    return 0;
}

}  // namespace atmos::cli
