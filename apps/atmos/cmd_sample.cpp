// atmos CLI: `atmos sample`.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "base/library_progress.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "harness/gallery.h"
#include "io/output_path.h"
#include "io/sample_io.h"
#include "render/progressive.h"
#include "sample_spectral.h"

namespace atmos::cli {

namespace {

struct SampleIo {
    std::string input, output;
    bool ground = false;    // --ground: the lit ground's radiance as a render shows it
    bool sun_disc = false;  // --sun-disc: the sun's disc as a render shows it
};

int CmdSample(const CommonOptions& common, const MonteCarloFlags& flags, const SampleIo& io,
              const SpectralFlags& spectral) {
    CheckSpectralFlagsNeedWavelengths(spectral);
    if (!io.output.empty() && io.output != "-") CheckOutputFile(io.output);  // before the work
    ThreadLimit limit(common.threads);
    const BackendScope backend(ParseBackend(common.backend));
    if (!spectral.wavelengths.empty()) {
        if (io.sun_disc) Fail("--sun-disc cannot be combined with --wavelengths");
        ParseWavelengths(spectral.wavelengths);  // fail before reading stdin
        const MonteCarloSettings mc = flags.Settings(CreateModel(GivenModel(common))->Info());
        const bool npy = !io.output.empty() && io.output != "-" && IsNpyPath(io.output);
        SpectralBatching batching = ParseSpectralBatching(spectral);
        // Baked tables are loaded per batch (PrepareModel): no wide path.
        if (!common.load.empty()) batching.wide = false;
        batching.prepare_wide = CliWidePrepare(common);
        std::vector<SampleQuery> queries = ReadQueries(io.input);
        for (SampleQuery& q : queries) q.ground = io.ground ? 1 : 0;
        return SampleSpectralCsv(common, mc, spectral.wavelengths, queries, batching, io.output,
                                 npy);
    }
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(GivenModel(common));
    const MonteCarloSettings monte_carlo = flags.Settings(model->Info());
    std::vector<SampleQuery> queries = ReadQueries(io.input);
    for (SampleQuery& q : queries) q.ground = io.ground ? 1 : 0;
    PrepareModel(common, atmosphere, model.get());
    const LibraryProgressScope progress(!common.quiet);  // long batches show a bar
    std::vector<SampleAnswer> answers = model->Info().capabilities.stochastic
                                            ? SampleMonteCarlo(*model, queries, monte_carlo)
                                            : model->Sample(queries);
    if (io.sun_disc) AddSunDisc(queries, atmosphere, &answers);
    WriteAnswers(io.output, queries, answers);
    return 0;
}

}  // namespace

Command AddSampleCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto flags = std::make_shared<MonteCarloFlags>();
    auto io = std::make_shared<SampleIo>();
    auto spectral = std::make_shared<SpectralFlags>();
    Command c;
    c.app = root->add_subcommand(
        "sample", "evaluate a model at queries read as CSV from stdin, answers to stdout");
    AddCommonOptions(c.app, common.get());
    AddBackendOption(c.app, &common->backend);
    AddMonteCarloFlags(c.app, flags.get());
    c.app->add_option("--input,-i", io->input,
                      "queries: a CSV file, or NPY of shape (N, 4) in the CSV's column order "
                      "(default: CSV from stdin)");
    c.app->add_option(
        "--output,-o", io->output,
        "answers: a CSV file, or NPY (float32, shape (N, 6): L_r,L_g,L_b,T_r,T_g,T_b) "
        "(default: CSV to stdout)");
    c.app->add_flag("--ground", io->ground,
                    "add the lit ground's reflected radiance (attenuated along the ray) to rays "
                    "that hit the ground, as render shows it");
    c.app->add_flag("--sun-disc", io->sun_disc,
                    "add the sun's disc (T / (pi alpha^2) per unit irradiance inside its angular "
                    "radius alpha) as render --sun-disc shows it");
    AddSpectralFlags(c.app, spectral.get(), false);
    c.run = [common, flags, io, spectral] { return CmdSample(*common, *flags, *io, *spectral); };
    return c;
}

}  // namespace atmos::cli
