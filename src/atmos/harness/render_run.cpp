// atmos: the work of `atmos render` (see render_run.h).
#include "harness/render_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

#include "atmos/error.h"
#include "atmos/image.h"
#include "base/parallel.h"
#include "harness/gallery.h"
#include "io/output_path.h"
#include "render/shards.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

RenderRequest ViewRequest(const View& view, int width, int height, Quantity quantity,
                          const MonteCarloSettings& monte_carlo) {
    RenderRequest request;
    request.view = view;
    request.width = width;
    request.height = height;
    request.quantity = quantity;
    request.show_progress = false;
    request.monte_carlo = monte_carlo;
    return request;
}

void CheckRenderRun(const RenderRun& run, double checkpoint_every) {
    if (!run.all_views && !run.split.sharded())
        ImageFormatFromPath(run.output);  // fail before the work on a bad name
    // The output is writable before any work (io/output_path.h); under
    // mpirun rank 0 writes it.
    if (run.split.world_rank != 0) {
    } else if (run.all_views) {
        CheckOutputDirectory(run.output);
    } else {
        CheckOutputFile(run.output);
    }
    // A named checkpoint's directory exists and is writable (atmos creates none).
    if (!run.checkpoint.empty()) CheckCheckpointFile(run.checkpoint + ".bin");
    if (!std::isfinite(run.exposure) || run.exposure < 0.0f) {
        Fail("--exposure must be a positive number");
    }
    if (!(checkpoint_every >= 0.0 && checkpoint_every <= 1e6)) {
        Fail("--checkpoint-every must be in [0, 1e6] seconds");
    }
}

void RenderViews(const RenderRun& run, Model* model, const std::vector<View>& views) {
    const int width = run.width, height = run.height;
    const Quantity quantity = run.quantity;
    const MonteCarloSettings& monte_carlo = run.monte_carlo;
    const RenderSplit& split = run.split;
    const bool all_views = run.all_views;
    const bool quiet = run.quiet;
    // An image written to a stream (/dev/stdout, a FIFO, /dev/null) has no
    // files beside it: no default checkpoint, no variance image.
    const bool stream_output = !all_views && IsStreamOutput(run.output);
    std::vector<GalleryEntry> gallery;
    if (all_views && split.world_rank == 0) fs::create_directories(run.output);
    for (const View& view : views) {
        RenderRequest request = ViewRequest(view, width, height, quantity, monte_carlo);
        request.sun_disc = run.sun_disc;
        request.show_progress = !quiet;
        MonteCarloShard shard = RenderSplitShard(split, run.pass_spp);
        const ShardScope shard_scope(split.split() ? &shard : nullptr);
        const bool stochastic = model->Info().capabilities.stochastic;
        Image variance;
        MonteCarloReport report;
        request.report = &report;
        std::string out_stem = fs::path(run.output).replace_extension().string();
        if (all_views) {
            out_stem = (fs::path(run.output) / (run.model + "-" + view.name)).string();
        }
        if (stochastic && quantity == Quantity::kRadiance) {
            request.checkpoint = run.checkpoint.empty() ? out_stem + ".ckpt"
                                 : all_views            ? run.checkpoint + "-" + view.name
                                                        : run.checkpoint;
            // Under mpirun each rank checkpoints its own passes.
            if (split.world_size > 1) {
                request.checkpoint += ".rank-" + std::to_string(split.world_rank + 1) + "-of-" +
                                      std::to_string(split.world_size);
            }
            request.resume = run.resume;
            if (!stream_output) request.variance = &variance;
            if (stream_output && run.checkpoint.empty()) request.checkpoint.clear();
        }
        Image image;
        const auto start = std::chrono::steady_clock::now();
        model->Render(request, &image);
        double seconds = Seconds(start);
        const float exposure = run.exposure > 0.0f               ? run.exposure
                               : quantity == Quantity::kRadiance ? view.exposure
                                                                 : 1.0f;
        auto drop_checkpoint = [&]() {
            // The output is written: its checkpoint has done its job (issue 18 item 10).
            if (!request.checkpoint.empty() && !run.keep_checkpoint) {
                std::error_code ignored;
                fs::remove(request.checkpoint + ".bin", ignored);
            }
        };
        if (split.sharded()) {
            WriteRenderShard(run.output, &shard, view.name, exposure, seconds);
            drop_checkpoint();
            if (!quiet) {
                std::fprintf(stderr,
                             "rendered shard %s of %-22s %dx%d with %s (%zu of %lld passes) in "
                             "%.3f s (%d threads)\n",
                             split.shard.c_str(), view.name.c_str(), width, height,
                             run.model.c_str(), shard.pass_images.size(),
                             static_cast<long long>(shard.passes), seconds, ParallelThreadCount());
            }
            continue;
        }
        if (split.world_size > 1) {
            // Every rank's passes to rank 0, merged there in pass order.
            std::vector<MonteCarloShard> shards = run.gather(std::move(shard));
            drop_checkpoint();
            if (split.world_rank != 0) continue;
            MergeRankShards(std::move(shards), &image, request.variance, &report);
            seconds = Seconds(start);
        }
        if (all_views) {
            const std::string stem = run.model + "-" + view.name;
            WriteImage(image, (fs::path(run.output) / (stem + ".png")).string(), exposure);
            WriteImage(image, (fs::path(run.output) / (stem + ".exr")).string(), exposure);
            gallery.push_back(
                {view.name, view.description, stem + ".png", stem + ".exr", seconds, exposure});
        } else {
            WriteImage(image, run.output, exposure);
        }
        if (!variance.empty()) WriteImage(variance, out_stem + ".variance.exr");
        drop_checkpoint();
        if (!quiet && report.noise >= 0.0) {
            std::fprintf(stderr,
                         "%s: noise %.4f (HDR-FLIP between its halves) at %lld paths per "
                         "pixel%s\n",
                         view.name.c_str(), report.noise, static_cast<long long>(report.samples),
                         report.noise <= monte_carlo.noise_target ? "" : " (the --spp cap)");
        }
        if (!quiet) {
            std::fprintf(
                stderr, "rendered %-22s %dx%d with %s in %.3f s (%d threads%s)\n",
                view.name.c_str(), width, height, run.model.c_str(), seconds, ParallelThreadCount(),
                split.world_size > 1
                    ? (" per rank, " + std::to_string(split.world_size) + " MPI ranks").c_str()
                    : "");
        }
    }
    if (all_views && split.world_rank == 0) {
        const ModelInfo& info = model->Info();
        const std::string page = (fs::path(run.output) / "index.html").string();
        WriteGalleryHtml(page, "atmos: " + info.title,
                         "model " + info.name + " (" + info.citation + "), atmosphere " +
                             run.atmosphere + ", " + run.size + ", " + run.quantity_name +
                             "; PNG: exposure, 1 - exp(-x), sRGB",
                         gallery);
        if (!quiet) std::fprintf(stderr, "wrote %s\n", page.c_str());
    }
}

void RenderSpectralViews(const RenderRun& run, const ModelSpec& spec,
                         const SpectralRenderFlags& flags, const std::vector<View>& views,
                         const PrepareFunction& prepare) {
    if (run.all_views) fs::create_directories(run.output);
    if (flags.load) Fail("--load cannot be combined with --wavelengths");
    const std::vector<double> nm = ParseWavelengths(flags.wavelengths);
    const ColourOutput colour = ParseColourOutput(flags.colour);
    const WhitePoint white = ParseWhitePoint(flags.white);
    SpectralBatching batching;
    batching.seeds = ParseBatchSeeds(flags.batch_seeds);
    batching.layout = ParseBatchLayout(flags.batch_layout);
    batching.wide = ParseChannelBatches(flags.channel_batches);
    batching.prepare_wide = flags.prepare_wide;
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(flags.atmosphere, flags.sets);
    const bool all_views = run.all_views;
    const int width = run.width, height = run.height;
    // Every view per batch: one Prepare per batch for all the views (in groups of
    // at most 1 GiB of spectral images).
    std::vector<RenderRequest> requests;
    for (const View& view : views) {
        requests.push_back(ViewRequest(view, width, height, run.quantity, run.monte_carlo));
        requests.back().sun_disc = run.sun_disc;
    }
    for (const std::vector<size_t>& group : SpectralRequestGroups(requests, nm.size())) {
        std::vector<RenderRequest> group_requests;
        for (size_t v : group) group_requests.push_back(requests[v]);
        const auto start = std::chrono::steady_clock::now();
        const std::vector<SpectralImage> spectra = RenderSpectralRequests(
            spec, atmosphere, nm, group_requests, prepare, nullptr, nullptr, batching);
        const double seconds = Seconds(start);
        if (!run.quiet) {
            std::fprintf(stderr,
                         "rendered %zu view(s) %dx%d with %s at %zu wavelengths (%zu batches) in "
                         "%.3f s\n",
                         group.size(), width, height, run.model.c_str(), nm.size(),
                         (nm.size() + 2) / 3, seconds);
        }
        for (size_t i = 0; i < group.size(); ++i) {
            const View& view = views[group[i]];
            const SpectralImage& spectral = spectra[i];
            const Image image = SpectralToColour(spectral, colour, white);
            const std::string output =
                all_views ? (fs::path(run.output) / (run.model + "-" + view.name + ".exr")).string()
                          : run.output;
            const std::string stem = fs::path(output).replace_extension().string();
            WriteImage(image, output, run.exposure > 0.0f ? run.exposure : view.exposure);
            WriteSpectralExr(spectral, stem + ".spectral.exr");
            if (!run.quiet) {
                std::fprintf(stderr, "wrote %s and %s.spectral.exr\n", output.c_str(),
                             stem.c_str());
            }
        }
    }
}

}  // namespace atmos
