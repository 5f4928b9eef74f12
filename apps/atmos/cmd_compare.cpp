// atmos CLI: `atmos compare`: every model against the reference at the 12 views
// (src/atmos/harness/compare.h), tables + images + index.html.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "harness/compare.h"
#include "harness/loc.h"
#include "harness/spectral_run.h"
#include "io/output_path.h"
#include "render/progressive.h"

namespace atmos::cli {

namespace {

// The reference model when none is given and `reference` is not registered.
constexpr const char* kStandInReference = "naive";
constexpr int kDefaultReferenceSpp = 64;
// The main job's default: a noise target (HDR-FLIP between the reference's
// halves), capped at kDefaultReferenceCap paths per pixel.
constexpr double kDefaultReferenceNoise = 0.01;
constexpr int kDefaultReferenceCap = 512;

struct CompareCliOptions {
    std::vector<std::string> models, views, sets;
    std::string size = "320x180";
    std::string quantity = "radiance";
    std::string reference;
    int64_t reference_spp = kDefaultReferenceSpp;
    int64_t reference_seed = 0;
    double reference_noise = kDefaultReferenceNoise;
    CLI::Option* spp_flag = nullptr;
    CLI::Option* noise_flag = nullptr;
    CLI::Option* seed_flag = nullptr;
    std::string atmosphere = "earth";
    std::string output;
    std::string cache = "out/cache";
    bool no_cache = false;
    CLI::Option* cache_flag = nullptr;
    bool no_npy = false;
    bool quiet = false;
    int threads = 0;
    std::string backend = "cpu";
    double ppd = 0.0;
    std::string tone_mapper = "aces";
    std::string exposure = "atmos";
    std::string command_line;
    SpectralFlags spectral;
    std::string reference_wavelengths;
    std::string shipped;
    CLI::Option* shipped_flag = nullptr;
    bool no_shipped = false;
};

bool IsRegistered(const std::string& name) {
    for (const ModelInfo& info : ListModels()) {
        if (info.name == name) return true;
    }
    return false;
}

int CmdCompare(const CompareCliOptions& o) {
    CompareConfig config;
    ParseSize(o.size, &config.width, &config.height);
    config.quantity = ParseQuantity(o.quantity);
    config.models = o.models;
    config.views = o.views;
    for (const std::string& v : o.views) GetView(v, AtmosphereParameters{});  // fail early
    for (const std::string& m : o.models) ParseModelSpec(m);                  // fail early
    config.atmosphere_name = o.atmosphere;
    config.atmosphere = LoadAtmosphere(o.atmosphere, o.sets);
    if (!o.spectral.wavelengths.empty()) {
        // Spectral: every model and the reference at the wavelengths, as linear sRGB
        // (harness/spectral_run.h); the render cache is not used.
        if (o.spectral.colour != "srgb") Fail("compare --wavelengths compares --colour srgb");
        config.wavelengths = ParseWavelengths(o.spectral.wavelengths);
        config.spectral_atmosphere = LoadSpectralAtmosphere(o.atmosphere, o.sets);
        config.white = ParseWhitePoint(o.spectral.white);
        for (const std::string& m : o.models)
            RequireSpectralModel(GetModelInfo(ParseModelSpec(m).name));
    }
    if (!o.reference_wavelengths.empty()) {
        // What RGB costs: the reference spectral (as linear sRGB), the models RGB.
        if (!o.spectral.wavelengths.empty()) {
            Fail("--reference-wavelengths compares the RGB models: drop --wavelengths");
        }
        if (config.quantity != Quantity::kRadiance) {
            Fail("--reference-wavelengths compares radiance");
        }
        if (o.spectral.colour != "srgb")
            Fail("compare --reference-wavelengths compares --colour srgb");
        config.reference_wavelengths = ParseWavelengths(o.reference_wavelengths);
        config.spectral_atmosphere = LoadSpectralAtmosphere(o.atmosphere, o.sets);
        config.white = ParseWhitePoint(o.spectral.white);
    }
    config.output_dir = !o.output.empty()                             ? o.output
                        : config.quantity == Quantity::kTransmittance ? "out/transmittance"
                                                                      : "out";
    // CUDA images may differ from CPU ones in the last bits: their own cache.
    // The cache lives under the output directory unless --cache names one.
    const std::string cache =
        o.cache_flag->count() > 0 ? o.cache : (o.output.empty() ? o.cache : o.output + "/cache");
    config.cache_dir = o.no_cache ? "" : o.backend == "cuda" ? cache + "/cuda" : cache;
    config.write_npy = !o.no_npy;
    config.show_progress = !o.quiet;
    CheckFlipPpd(o.ppd);
    config.flip.ppd = o.ppd;
    config.flip.tone_mapper = ParseFlipToneMapper(o.tone_mapper);
    config.flip.exposure_setup = ParseFlipExposureSetup(o.exposure);
    config.command_line = o.command_line;
    config.batching = ParseSpectralBatching(o.spectral);

    // The reference: `reference` (the path tracer) when registered, else a stand-in.
    const bool monte_carlo_given =
        o.spp_flag->count() + o.seed_flag->count() + o.noise_flag->count() > 0;
    if (!o.reference.empty()) {
        const ModelSpec reference = ParseModelSpec(o.reference);
        config.reference_model = reference.name;
        config.reference_options = reference.options;
        config.reference_note = "chosen with --reference " + o.reference;
    } else if (IsRegistered("reference")) {
        config.reference_model = "reference";
        config.reference_note = "the path tracer";
    } else {
        config.reference_model = kStandInReference;
        config.reference_options = {{"steps", "256"}, {"light-steps", "64"}};
        config.reference_note =
            "stand-in: the path tracer `reference` is not registered in this build";
    }
    if (GetModelInfo(config.reference_model).capabilities.stochastic) {
        if (!(o.reference_noise >= 0.0 && o.reference_noise < 1.0)) {
            Fail("--reference-noise must be in [0, 1) (0: a fixed --reference-spp), got ",
                 o.reference_noise);
        }
        // The default is a noise target capped at kDefaultReferenceCap paths;
        // --reference-spp alone is a fixed count (noise off), with
        // --reference-noise the cap.
        const bool noise_given = o.noise_flag->count() > 0;
        const bool spp_given = o.spp_flag->count() > 0;
        const double noise = noise_given ? o.reference_noise : spp_given ? 0.0 : o.reference_noise;
        const int64_t spp = noise > 0.0 && !spp_given ? kDefaultReferenceCap : o.reference_spp;
        config.reference_monte_carlo =
            MakeMonteCarloSettings(spp, o.reference_seed, 0, "--reference-spp", "--reference-seed");
        config.reference_monte_carlo.noise_target = noise;
    } else if (monte_carlo_given) {
        Fail(
            "--reference-spp, --reference-seed and --reference-noise need a Monte Carlo "
            "reference model (",
            config.reference_model, " is not one)");
    }
    CreateModel(config.reference_model, config.reference_options);  // validate the options
    // Shipped references (harness/shipped_references.h): --shipped-references DIR,
    // else data/references/WxH of the source tree when it exists and the
    // reference renders to a noise target (a fixed --reference-spp asks for that
    // estimate: shipped ones only when named); --no-shipped-references: never.
    const bool shipped_applies = GetModelInfo(config.reference_model).capabilities.stochastic &&
                                 config.quantity == Quantity::kRadiance &&
                                 config.wavelengths.empty() && o.reference_wavelengths.empty();
    if (o.shipped_flag->count() > 0) {
        if (o.no_shipped) {
            Fail("--shipped-references and --no-shipped-references exclude each other");
        }
        std::error_code ec;
        if (!std::filesystem::is_directory(o.shipped, ec)) {
            Fail("--shipped-references: '", o.shipped, "' is not a directory");
        }
        if (!shipped_applies) {
            Fail(
                "--shipped-references: shipped references stand for a Monte Carlo reference's "
                "RGB radiance (not with --quantity transmittance, --wavelengths or "
                "--reference-wavelengths)");
        }
        config.shipped_references = o.shipped;
    } else if (!o.no_shipped && shipped_applies &&
               config.reference_monte_carlo.noise_target > 0.0) {
        const std::filesystem::path dir =
            std::filesystem::path(DefaultSourceDir()) / "data" / "references" /
            (std::to_string(config.width) + "x" + std::to_string(config.height));
        std::error_code ec;
        if (std::filesystem::is_directory(dir, ec)) config.shipped_references = dir.string();
    }
    if (!config.reference_wavelengths.empty()) {
        config.reference_note += "; rendered spectrally at " +
                                 std::to_string(config.reference_wavelengths.size()) +
                                 " wavelengths (--reference-wavelengths), the models in RGB; "
                                 "rgb_cost.csv compares each model with the RGB reference too";
    }

    CheckOutputDirectory(config.output_dir);  // after the flags, before the work (io/output_path.h)
    ThreadLimit limit(o.threads);
    const BackendScope backend(ParseBackend(o.backend));
    const CompareResult r = RunCompare(config);
    if (!o.quiet) {
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
    o->command_line = cl.str();
    CLI::App* cmd = root->add_subcommand(
        "compare", "every model against the reference: FLIP, RMSE, images, index.html");
    cmd->add_option("--models", o->models,
                    "models (default: all but the reference); NAME:OPTION=VALUE[:...] compares a "
                    "model with options, e.g. hillaire:segment-offset=0.5")
        ->delimiter(',');
    cmd->add_option("--views", o->views, "views (default: all 12; transmittance: 5)")
        ->delimiter(',');
    cmd->add_option("--size,-s", o->size, "image size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--quantity", o->quantity, "radiance (HDR-FLIP) or transmittance (LDR-FLIP)")
        ->capture_default_str();
    o->noise_flag =
        cmd->add_option("--reference-noise", o->reference_noise,
                        "noise target of a Monte Carlo reference: each view renders until the "
                        "HDR-FLIP between its two halves (even and odd passes) is at or below it, "
                        "at most --reference-spp paths per pixel (default then " +
                            std::to_string(kDefaultReferenceCap) +
                            "); 0, or "
                            "--reference-spp given alone: a fixed --reference-spp (two halves of "
                            "spp/2, seeds 2s+1 and 2s+2)")
            ->capture_default_str();
    o->spp_flag = cmd->add_option("--reference-spp", o->reference_spp,
                                  "paths per pixel of a Monte Carlo reference: alone, a fixed "
                                  "count (two halves of spp/2; default below); with "
                                  "--reference-noise, the cap. Effective cap when neither is "
                                  "given (the default noise target): " +
                                      std::to_string(kDefaultReferenceCap))
                      ->capture_default_str();
    o->seed_flag = cmd->add_option("--reference-seed", o->reference_seed,
                                   "random seed s of a Monte Carlo reference, in [0, 4294967295]")
                       ->capture_default_str();
    cmd->add_option("--reference", o->reference,
                    "reference model and its options, NAME[:OPTION=VALUE...] (default: "
                    "`reference` when registered, else naive:steps=256:light-steps=64)");
    o->shipped_flag = cmd->add_option(
        "--shipped-references", o->shipped,
        "a directory of shipped references (scripts/make_references.sh): a view whose "
        "provenance matches the run (atmosphere, view, reference options, size, estimator "
        "version) and whose noise is at or below --reference-noise, or whose paths per pixel "
        "reach --reference-spp, is read instead of rendered (default: data/references/WxH of "
        "the source tree when it exists and the reference renders to a noise target)");
    cmd->add_flag("--no-shipped-references", o->no_shipped,
                  "render every view's reference: read no shipped references");
    cmd->add_option("--atmosphere,-a", o->atmosphere, "preset name or JSON file")
        ->capture_default_str();
    cmd->add_option("--set", o->sets, "override one atmosphere field: FIELD=VALUE (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("-o,--output", o->output,
                    "output directory (default out, or out/transmittance)");
    o->cache_flag = cmd->add_option("--cache", o->cache,
                                    "render cache directory (default: out/cache, or DIR/cache "
                                    "with -o DIR)");
    cmd->add_flag("--no-cache", o->no_cache, "render everything, read and write no cache");
    cmd->add_flag("--no-npy", o->no_npy, "do not write .npy images");
    cmd->add_option("--ppd", o->ppd, "FLIP pixels per degree (default 67.0206)");
    cmd->add_option("--tonemapper", o->tone_mapper, "HDR-FLIP tone mapper: aces, hable, reinhard")
        ->capture_default_str();
    cmd->add_option("--exposure", o->exposure,
                    "HDR-FLIP black pixels: atmos (exposure median over the non-black pixels) or "
                    "thesis (seed 003 section 11.5: 1e-9 added to every pixel)")
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)")
        ->check(CLI::Range(0, 4096));  // (NonNegativeNumber printed a 309-digit bound)
    cmd->add_flag("--quiet,-q", o->quiet, "no progress lines");
    AddBackendOption(cmd, &o->backend);
    AddSpectralFlags(cmd, &o->spectral);
    cmd->add_option(
        "--reference-wavelengths", o->reference_wavelengths,
        "what RGB costs: the reference rendered at these wavelengths (as --wavelengths; "
        "linear sRGB with --white), the models in RGB; each model's FLIP against it "
        "and against the RGB reference in rgb_cost.csv");
    Command c;
    c.app = cmd;
    c.run = [o] { return CmdCompare(*o); };
    return c;
}

}  // namespace atmos::cli
