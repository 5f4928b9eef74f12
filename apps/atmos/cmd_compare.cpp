// atmos CLI: `atmos compare`: the flags of the compare study (studies/compare.h:
// every model against the reference at the 12 views), tables + images + index.html.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/spectral.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "io/output_path.h"
#include "studies/compare.h"

namespace atmos::cli {

namespace {

struct CompareCliOptions {
    CompareRequest request;
    StudyFlags study;
    std::string size = "320x180";
    int64_t reference_spp = kCompareReferenceSpp;
    int64_t reference_seed = 0;
    double reference_noise = kCompareReferenceNoise;
    std::string reference, cache, shipped;
    CLI::Option *spp_flag = nullptr, *noise_flag = nullptr, *seed_flag = nullptr;
    CLI::Option *reference_flag = nullptr, *cache_flag = nullptr, *shipped_flag = nullptr;
    bool no_npy = false;
    SpectralFlags spectral;
    std::string reference_wavelengths;
};

int CmdCompare(CompareCliOptions o) {
    CompareRequest& q = o.request;
    ParseSize(o.size, &q.width, &q.height);
    if (o.reference_flag->count() > 0) q.reference = o.reference;
    if (o.spp_flag->count() > 0) q.reference_spp = o.reference_spp;
    if (o.seed_flag->count() > 0) q.reference_seed = o.reference_seed;
    if (o.noise_flag->count() > 0) q.reference_noise = o.reference_noise;
    if (o.cache_flag->count() > 0) q.cache_dir = o.cache;
    if (o.shipped_flag->count() > 0) q.shipped_references = o.shipped;
    q.atmosphere = o.study.atmosphere;
    q.sets = o.study.sets;
    q.cuda = o.study.backend == "cuda";
    q.write_npy = !o.no_npy;
    q.show_progress = !o.study.quiet;
    if (!o.spectral.wavelengths.empty()) q.wavelengths = ParseWavelengths(o.spectral.wavelengths);
    if (!o.reference_wavelengths.empty()) {
        q.reference_wavelengths = ParseWavelengths(o.reference_wavelengths);
    }
    q.colour = o.spectral.colour;
    q.white = o.spectral.white;
    q.batching = ParseSpectralBatching(o.spectral);
    const CompareConfig config = ResolveCompareConfig(q);
    CheckOutputDirectory(config.output_dir);  // after the flags, before the work (io/output_path.h)
    ThreadLimit limit(o.study.threads);
    const BackendScope backend(ParseBackend(o.study.backend));
    const CompareResult r = RunCompare(config);
    WriteCompareImages(config, r);
    WriteCompareTables(config, r);
    if (!o.study.quiet) {
        std::fprintf(stderr, "compared %zu models at %zu views in %.1f s (%d threads)\n",
                     r.models.size(), r.rows.size(), r.total_seconds, r.threads);
    }
    std::printf("reference: %s\n", config.reference_model.c_str());
    std::printf("wrote %s/flip.csv, %s/rmse.csv, %s/index.html\n", config.output_dir.c_str(),
                config.output_dir.c_str(), config.output_dir.c_str());
    return 0;
}

}  // namespace

Command AddCompareCommand(CLI::App* root, int argc, char** argv) {
    auto o = std::make_shared<CompareCliOptions>();
    std::ostringstream cl;
    for (int i = 0; i < argc; ++i) cl << (i ? " " : "") << argv[i];
    o->request.command_line = cl.str();
    CLI::App* cmd = root->add_subcommand(
        "compare", "every model against the reference: FLIP, RMSE, images, index.html");
    cmd->add_option("--models", o->request.models,
                    "models (default: all but the reference); NAME:OPTION=VALUE[:...] compares a "
                    "model with options, e.g. hillaire:segment-offset=0.5")
        ->delimiter(',');
    cmd->add_option("--views", o->request.views, kCompareViewsHelp)->delimiter(',');
    cmd->add_flag("--luminance", o->request.luminance, kCompareLuminanceHelp);
    cmd->add_option("--size,-s", o->size, "image size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--quantity", o->request.quantity,
                    "radiance (HDR-FLIP) or transmittance (LDR-FLIP)")
        ->capture_default_str();
    o->noise_flag =
        cmd->add_option("--reference-noise", o->reference_noise,
                        "noise target of a Monte Carlo reference: each view renders until the "
                        "HDR-FLIP between its two halves (even and odd passes) is at or below it, "
                        "at most --reference-spp paths per pixel (default then " +
                            std::to_string(kCompareReferenceCap) +
                            "); 0, or "
                            "--reference-spp given alone: a fixed --reference-spp (two halves of "
                            "spp/2, seeds 2s+1 and 2s+2)")
            ->capture_default_str();
    o->spp_flag = cmd->add_option("--reference-spp", o->reference_spp,
                                  "paths per pixel of a Monte Carlo reference: alone, a fixed "
                                  "count (two halves of spp/2; default below); with "
                                  "--reference-noise, the cap. Effective cap when neither is "
                                  "given (the default noise target): " +
                                      std::to_string(kCompareReferenceCap))
                      ->capture_default_str();
    o->seed_flag = cmd->add_option("--reference-seed", o->reference_seed,
                                   "random seed s of a Monte Carlo reference, in [0, 4294967295]")
                       ->capture_default_str();
    o->reference_flag =
        cmd->add_option("--reference", o->reference,
                        "reference model and its options, NAME[:OPTION=VALUE...] (default: "
                        "the path tracer `reference`)");
    o->shipped_flag = cmd->add_option(
        "--shipped-references", o->shipped,
        "a directory of shipped references (scripts/make_references.sh): a view whose "
        "provenance matches the run (atmosphere, view, reference options, size, estimator "
        "version) and whose noise is at or below --reference-noise, or whose paths per pixel "
        "reach --reference-spp, is read instead of rendered (default: data/references/WxH of "
        "the source tree when it exists and the reference renders to a noise target)");
    cmd->add_flag("--no-shipped-references", o->request.no_shipped,
                  "render every view's reference: read no shipped references");
    cmd->add_option("-o,--output", o->request.output_dir,
                    "output directory (default out, or out/transmittance)");
    o->cache_flag = cmd->add_option("--cache", o->cache,
                                    "render cache directory (default: out/cache, or DIR/cache "
                                    "with -o DIR)");
    cmd->add_flag("--no-cache", o->request.no_cache, "render everything, read and write no cache");
    cmd->add_flag("--no-npy", o->no_npy, "do not write .npy images");
    cmd->add_option("--ppd", o->request.ppd, "FLIP pixels per degree (default 67.0206)");
    cmd->add_option("--tonemapper", o->request.tone_mapper,
                    "HDR-FLIP tone mapper: aces, hable, reinhard")
        ->capture_default_str();
    cmd->add_option("--exposure", o->request.exposure,
                    "HDR-FLIP black pixels: atmos (exposure median over the non-black pixels) or "
                    "thesis (Leenman 2025 section 11.5: 1e-9 added to every pixel)")
        ->capture_default_str();
    AddStudyFlags(cmd, &o->study, true, "no progress lines");
    AddSpectralFlags(cmd, &o->spectral);
    cmd->add_option(
        "--reference-wavelengths", o->reference_wavelengths,
        "what RGB costs: the reference rendered at these wavelengths (as --wavelengths; "
        "linear sRGB with --white), the models in RGB; each model's FLIP against it "
        "and against the RGB reference in rgb_cost.csv");
    return {cmd, [o] { return CmdCompare(*o); }};
}

}  // namespace atmos::cli
