#include "cli_common.h"

#include <cstdio>

#include "atmos/error.h"
#include "atmos/model.h"
#include "base/library_progress.h"
#include "harness/table_cache.h"

namespace atmos::cli {

namespace {
bool g_strict = false;
}  // namespace

bool StrictRequested() { return g_strict; }

// --atmosphere, --set and --threads (every command that runs a model).
void AddAtmosphereOptions(CLI::App* cmd, std::string* atmosphere, std::vector<std::string>* sets,
                          int* threads) {
    cmd->add_option("--atmosphere,-a", *atmosphere, "preset name or JSON file")
        ->capture_default_str();
    cmd->add_option("--set", *sets, "override one atmosphere field: FIELD=VALUE (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--threads", *threads, "worker threads (0: all cores)")
        ->check(CLI::Range(0, 4096));  // (NonNegativeNumber printed a 309-digit bound)
}

void AddCommonOptions(CLI::App* cmd, CommonOptions* o) {
    cmd->add_option("--model,-m", o->model,
                    "the model and its options: NAME[:OPTION=VALUE...], e.g. bruneton:orders=2 "
                    "(`atmos list NAME` prints a model's options and defaults)")
        ->capture_default_str();
    AddAtmosphereOptions(cmd, &o->atmosphere, &o->sets, &o->threads);
    cmd->add_flag("--quiet,-q", o->quiet, "no progress bar or timing lines");
    cmd->add_flag("--strict", g_strict,
                  "fail (exit 2) when the output guard had to replace a NaN, infinite or "
                  "negative value by 0 (default: a warning)");
    cmd->add_option("--load", o->load,
                    "read the model's tables from a directory written by `atmos bake` instead of "
                    "precomputing them");
    cmd->add_flag("--no-cache", o->no_cache,
                  "precompute the model's tables: neither read nor write the table cache "
                  "($XDG_CACHE_HOME/atmos/tables, else ~/.cache/atmos/tables; also "
                  "ATMOS_NO_CACHE=1; size limit ATMOS_CACHE_MAX_MB, default 2048)");
}

void AddStudyFlags(CLI::App* cmd, StudyFlags* flags, bool backend, const char* quiet_help) {
    AddAtmosphereOptions(cmd, &flags->atmosphere, &flags->sets, &flags->threads);
    if (quiet_help) cmd->add_flag("--quiet,-q", flags->quiet, quiet_help);
    if (backend) AddBackendOption(cmd, &flags->backend);
}

void AddBackendOption(CLI::App* cmd, std::string* backend) {
    cmd->add_option("--backend", *backend,
                    "where pixels are computed: cpu, or cuda (a build with -DATMOS_CUDA=ON and a "
                    "CUDA device)")
        ->capture_default_str();
}

ModelSpec GivenModel(const CommonOptions& o) { return ParseModelSpec(o.model); }

// "WxH" with 1 <= W, H <= 16384.
void ParseSize(const std::string& text, int* width, int* height) {
    const size_t x = text.find('x');
    auto parse = [&](const std::string& part, int* out) {
        if (part.empty() || part.size() > 6 ||
            part.find_first_not_of("0123456789") != std::string::npos) {
            return false;
        }
        *out = std::stoi(part);
        return *out >= 1 && *out <= 16384;
    };
    if (x == std::string::npos || !parse(text.substr(0, x), width) ||
        !parse(text.substr(x + 1), height)) {
        Fail("malformed size '", text, "': expected WIDTHxHEIGHT, each in [1, 16384]");
    }
}

double Seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double PrepareModel(const CommonOptions& o, const AtmosphereParameters& atmosphere, Model* model) {
    const auto start = std::chrono::steady_clock::now();
    // Precomputations over a second show a progress bar (issue 18 item 9).
    const LibraryProgressScope progress(!o.quiet);
    if (o.load.empty()) {
        // Through the table cache (harness/table_cache.h) for models with
        // tables; the model was created from o.model.
        const TablePrepareResult r = PrepareWithTableCache(model, GivenModel(o).options, atmosphere,
                                                           UserTableCache(o.no_cache));
        if (r.from_cache && !o.quiet) {
            std::fprintf(stderr,
                         "tables of %s from the cache %s (computed in %.3f s; --no-cache "
                         "to recompute)\n",
                         o.model.c_str(), r.entry.c_str(), r.prepare_seconds);
        }
    } else {
        model->LoadBaked(o.load, atmosphere);
    }
    return Seconds(start);
}

WidePrepareFunction CliWidePrepare(const CommonOptions& o) {
    return [&o](const std::vector<AtmosphereParameters>& group, Model* model,
                const PrepareFunction& prepare) {
        const TableCacheSettings cache = UserTableCache(o.no_cache);
        bool cached = o.load.empty() && !group.empty();
        for (const AtmosphereParameters& a : group) {
            cached = cached && TableCacheHasEntry(*model, GivenModel(o).options, a, cache);
        }
        if (cached || !o.load.empty()) {
            model->PrepareWide(group, prepare);
            return;
        }
        const LibraryProgressScope progress(!o.quiet);
        model->PrepareWide(group);
    };
}

void CheckSpectralFlagsNeedWavelengths(const SpectralFlags& flags) {
    if (!flags.wavelengths.empty()) return;
    const SpectralFlags defaults;
    const char* given = flags.colour != defaults.colour                     ? "--colour"
                        : flags.white != defaults.white                     ? "--white"
                        : flags.batch_seeds != defaults.batch_seeds         ? "--batch-seeds"
                        : flags.batch_layout != defaults.batch_layout       ? "--batch-layout"
                        : flags.channel_batches != defaults.channel_batches ? "--channel-batches"
                                                                            : nullptr;
    if (given) Fail(given, " applies to a spectral run only: give --wavelengths too");
}

SpectralBatching ParseSpectralBatching(const SpectralFlags& flags) {
    SpectralBatching batching;
    batching.seeds = ParseBatchSeeds(flags.batch_seeds);
    batching.layout = ParseBatchLayout(flags.batch_layout);
    batching.wide = ParseChannelBatches(flags.channel_batches);
    return batching;
}

void AddSpectralFlags(CLI::App* cmd, SpectralFlags* flags, bool colour) {
    cmd->add_option("--wavelengths", flags->wavelengths,
                    "spectral run: START:STOP:COUNT (nm, both ends included) or a list a,b,c; "
                    "the atmosphere is evaluated at each wavelength and the model run in "
                    "batches of three");
    cmd->add_option("--batch-seeds", flags->batch_seeds,
                    "with --wavelengths, Monte Carlo models: distinct (batch b uses seed + b "
                    "2^40: independent batches) or same (every batch of three wavelengths uses "
                    "the seed: less noise in each wavelength's own value with consecutive "
                    "batches, more in colour)")
        ->capture_default_str();
    cmd->add_option(
           "--batch-layout", flags->batch_layout,
           "with --wavelengths: interleaved (batch b holds wavelengths b, b+S, b+2S "
           "with S = ceil(N/3): hero-wavelength companions spread over the range; with "
           "distinct seeds the least colour noise at equal time) or consecutive (3b..3b+2)")
        ->capture_default_str();
    cmd->add_option("--channel-batches", flags->channel_batches,
                    "with --wavelengths: wide (a model with wide channel batches is prepared "
                    "once for up to 16 batches of three and shares each ray's geometry across "
                    "their channels: the same values, faster) or three (a model per batch)")
        ->capture_default_str();
    if (!colour) return;
    cmd->add_option("--colour", flags->colour,
                    "with --wavelengths: the colour of the RGB output, srgb (linear) or xyz "
                    "(CIE 1931 2-degree)")
        ->capture_default_str();
    cmd->add_option("--white", flags->white,
                    "with --wavelengths and --colour srgb: d65 (the sRGB matrix as is) or e "
                    "(Bradford from the equal-energy white: a flat spectrum is grey)")
        ->capture_default_str();
}

}  // namespace atmos::cli
