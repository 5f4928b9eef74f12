// atmos CLI: `atmos sample --wavelengths ...` (issue 17), kept apart from
// cmd_sample.cpp's RGB reading and printing; the columns are
// studies/spectral_sample.h's.
#include <cstdio>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "cli_common.h"
#include "harness/spectral_run.h"
#include "io/image_formats.h"
#include "io/output_path.h"
#include "sample_spectral.h"
#include "studies/spectral_sample.h"

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
    if (npy) {
        const std::vector<float> array = SpectralSampleArray(nm, queries.size(), values);
        WriteThroughTemporary(output, [&](const std::string& temporary) {
            detail::WriteNpyArray(temporary, {queries.size(), nm.size() + 3}, array.data());
        });
        return 0;
    }
    const std::string text = SpectralSampleCsv(nm, queries, values);
    if (!output.empty() && output != "-") {
        WriteFileAtomically(output, text);
        return 0;
    }
    const bool ok = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
    if (!ok || std::fflush(stdout) != 0) Fail("cannot write the spectral columns to stdout");
    return 0;
}

}  // namespace atmos::cli
