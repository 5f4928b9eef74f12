// atmos CLI: `atmos sample --wavelengths ...` (issue 17), kept apart from
// cmd_sample.cpp's RGB reading and printing.
//
// Columns: altitude_m, mu, mu_s, azimuth_deg, one L_<nm> per wavelength (spectral
// radiance: the atmosphere's solar spectrum times the radiance per unit
// irradiance, no sun disc, no ground; W m^-2 sr^-1 nm^-1 for a solar spectrum in
// W m^-2 nm^-1), then X, Y, Z: 683 lm/W times the CIE 1931 integral over the given
// bins (cd m^-2 for those units).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "cli_common.h"
#include "harness/spectral_run.h"
#include "io/image_formats.h"
#include "io/output_path.h"
#include "sample_spectral.h"

namespace atmos::cli {

int SampleSpectralCsv(const CommonOptions& common, const MonteCarloSettings& monte_carlo,
                      const std::string& wavelengths, const std::vector<SampleQuery>& queries,
                      SpectralBatching batching, const std::string& output, bool npy) {
    if (!common.load.empty()) Fail("--load cannot be combined with --wavelengths");
    const std::vector<double> nm = ParseWavelengths(wavelengths);
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(common.atmosphere, common.sets);
    const std::vector<double> values = SampleSpectral(
        GivenModel(common), atmosphere, nm, queries, monte_carlo,
        [&](const AtmosphereParameters& a, Model* model) { PrepareModel(common, a, model); },
        batching);
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
        WriteThroughTemporary(output, [&](const std::string& temporary) {
            detail::WriteNpyArray(temporary, {queries.size(), n + 3}, array.data());
        });
        return 0;
    }
    // The CSV in memory, then to stdout or through a temporary file and one
    // rename (a failed write never leaves a truncated file).
    std::string text;
    char cell[64];
    // A number as printf's %.17g (the query's inputs) or %.9g (float outputs).
    const auto put = [&](bool comma, bool full_precision, double v) {
        if (comma) text += ',';
        const int len = full_precision ? std::snprintf(cell, sizeof cell, "%.17g", v)
                                       : std::snprintf(cell, sizeof cell, "%.9g", v);
        text.append(cell, static_cast<size_t>(std::max(len, 0)));
    };
    text += "altitude_m,mu,mu_s,azimuth_deg";
    for (double l : nm) text += ",L_" + WavelengthLabel(l);
    text += ",X,Y,Z\n";
    for (size_t q = 0; q < queries.size(); ++q) {
        put(false, true, queries[q].altitude_m);
        put(true, true, queries[q].mu);
        put(true, true, queries[q].mu_s);
        put(true, true, queries[q].azimuth_deg);
        for (size_t i = 0; i < n; ++i) put(true, false, values[q * n + i]);
        const Vec3d xyz = SpectrumToXyz(nm, weights, values.data() + q * n);
        put(true, false, kMaxLuminousEfficacy * xyz.x);
        put(true, false, kMaxLuminousEfficacy * xyz.y);
        put(true, false, kMaxLuminousEfficacy * xyz.z);
        text += "\n";
    }
    if (!output.empty() && output != "-") {
        WriteFileAtomically(output, text);
        return 0;
    }
    const bool ok = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
    if (!ok || std::fflush(stdout) != 0) Fail("cannot write the spectral columns to stdout");
    return 0;
}

}  // namespace atmos::cli
