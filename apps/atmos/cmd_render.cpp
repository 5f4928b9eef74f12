// atmos CLI: `atmos render`.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "harness/gallery.h"
#include "harness/spectral_run.h"
#include "io/output_path.h"
#include "mpi_world.h"
#include "render/progressive.h"
#include "render/shards.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

struct RenderOptions {
    std::string view = "ground-noon";
    std::string size = "480x270";
    std::string quantity = "radiance";
    std::string output;
    bool sun_disc = false;
    std::string camera;  // --camera KEY=VALUE,... (a free camera, docs/views.md)
    std::string sun;     // --sun elevation=DEG,azimuth=DEG
    bool view_given = false;
    float exposure = 0.0f;   // 0: the view's
    std::string checkpoint;  // Monte Carlo models: checkpoint stem (default: OUTPUT.ckpt)
    bool resume = false;
    bool keep_checkpoint = false;
    double checkpoint_every = 10.0;  // seconds between checkpoints, at most
    std::string shard;               // --shard K/N (issue 36)
    int64_t extend_from = 0;         // --extend-from SPP: a later round of shards
    MonteCarloFlags monte_carlo;
    SpectralFlags spectral;
};

// --shard K/N: K and N (1 <= K <= N); one error naming the flag otherwise.
void ParseShard(const std::string& text, int64_t* index, int64_t* count) {
    const size_t slash = text.find('/');
    long long k = 0, n = 0;
    size_t used_k = 0, used_n = 0;
    bool ok = slash != std::string::npos && slash > 0 && slash + 1 < text.size();
    try {
        if (ok) {
            k = std::stoll(text.substr(0, slash), &used_k);
            n = std::stoll(text.substr(slash + 1), &used_n);
        }
    } catch (const std::exception&) {
        ok = false;
    }
    ok = ok && used_k == slash && used_n == text.size() - slash - 1 && n >= 1 && n <= 1000000 &&
         k >= 1 && k <= n;
    if (!ok) {
        Fail("--shard must be K/N with 1 <= K <= N <= 1000000 (shard K of N, e.g. 2/8), got '",
             text, "'");
    }
    *index = k - 1;
    *count = n;
}

bool EndsWith(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// --wavelengths: the views rendered at each wavelength (harness/spectral_run.h);
// OUTPUT gets the colour (--colour, --white), STEM.spectral.exr the spectrum.
int RenderSpectralViews(const CommonOptions& common, const RenderOptions& ro,
                        const std::vector<View>& views, int width, int height, Quantity quantity,
                        const MonteCarloSettings& monte_carlo) {
    if (!common.load.empty()) Fail("--load cannot be combined with --wavelengths");
    const std::vector<double> nm = ParseWavelengths(ro.spectral.wavelengths);
    const ColourOutput colour = ParseColourOutput(ro.spectral.colour);
    const WhitePoint white = ParseWhitePoint(ro.spectral.white);
    const SpectralBatching batching = ParseSpectralBatching(ro.spectral);
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(common.atmosphere, common.sets);
    const bool all_views = ro.view == "all";
    // Every view per batch: one Prepare per batch for all the views (in groups of
    // at most 1 GiB of spectral images).
    std::vector<RenderRequest> requests;
    for (const View& view : views) {
        requests.push_back(ViewRequest(view, width, height, quantity, monte_carlo));
        requests.back().sun_disc = ro.sun_disc;
    }
    for (const std::vector<size_t>& group : SpectralRequestGroups(requests, nm.size())) {
        std::vector<RenderRequest> group_requests;
        for (size_t v : group) group_requests.push_back(requests[v]);
        const auto start = std::chrono::steady_clock::now();
        const std::vector<SpectralImage> spectra = RenderSpectralRequests(
            GivenModel(common), atmosphere, nm, group_requests,
            [&](const AtmosphereParameters& a, Model* model) { PrepareModel(common, a, model); },
            nullptr, nullptr, batching);
        const double seconds = Seconds(start);
        if (!common.quiet) {
            std::fprintf(stderr,
                         "rendered %zu view(s) %dx%d with %s at %zu wavelengths (%zu batches) in "
                         "%.3f s\n",
                         group.size(), width, height, common.model.c_str(), nm.size(),
                         (nm.size() + 2) / 3, seconds);
        }
        for (size_t i = 0; i < group.size(); ++i) {
            const View& view = views[group[i]];
            const SpectralImage& spectral = spectra[i];
            const Image image = SpectralToColour(spectral, colour, white);
            const std::string output =
                all_views
                    ? (fs::path(ro.output) / (common.model + "-" + view.name + ".exr")).string()
                    : ro.output;
            const std::string stem = fs::path(output).replace_extension().string();
            WriteImage(image, output, ro.exposure > 0.0f ? ro.exposure : view.exposure);
            WriteSpectralExr(spectral, stem + ".spectral.exr");
            if (!common.quiet) {
                std::fprintf(stderr, "wrote %s and %s.spectral.exr\n", output.c_str(),
                             stem.c_str());
            }
        }
    }
    return 0;
}

int CmdRender(const CommonOptions& common, const RenderOptions& ro) {
    int width = 0, height = 0;
    ParseSize(ro.size, &width, &height);
    const Quantity quantity = ParseQuantity(ro.quantity);
    if (ro.output.empty()) Fail("render needs an output: -o FILE (or -o DIR with --view all)");
    const bool all_views = ro.view == "all";
    // A free camera and sun (--camera, --sun): checked before any work.
    const bool custom = !ro.camera.empty() || !ro.sun.empty();
    CameraSpec camera_spec;
    Vec3d sun_direction;
    if (custom) {
        if (ro.view_given) Fail("--view cannot be combined with --camera or --sun");
        if (ro.sun.empty()) Fail("--camera needs --sun elevation=DEG,azimuth=DEG");
        if (!ro.camera.empty()) camera_spec = ParseCameraSpec(ro.camera);
        CheckCameraSpec(camera_spec, width, height);
        sun_direction = ParseSunSpec(ro.sun);
    }
    // --shard K/N (or the ranks of mpirun): the passes of one Monte Carlo
    // radiance render, split (render/shards.h).
    const bool sharded = !ro.shard.empty();
    int64_t shard_index = 0, shard_count = 1;
    const MpiWorld& world = World();
    if (sharded) {
        ParseShard(ro.shard, &shard_index, &shard_count);
        if (world.size > 1) {
            Fail("--shard cannot be combined with mpirun (the ranks are the shards)");
        }
        if (all_views) Fail("--shard renders one view: give --view NAME, not --view all");
        if (!EndsWith(ro.output, ".shard") && !IsStreamOutput(ro.output)) {
            Fail("--shard writes the shard's passes, not an image: -o must end in .shard (got '",
                 ro.output, "'); `atmos merge` makes the image");
        }
    } else if (EndsWith(ro.output, ".shard")) {
        Fail("-o ", ro.output, ": a .shard output needs --shard K/N");
    }
    if (ro.extend_from != 0) {
        // A later round: the passes after the first EXTEND paths per pixel.
        const int64_t pass_spp = ro.monte_carlo.pass_spp;
        if (!sharded) Fail("--extend-from needs --shard K/N (a later round of shards)");
        if (pass_spp <= 0) {
            Fail("--extend-from needs --pass-spp P (the same in every round: it fixes the passes)");
        }
        if (ro.extend_from < 0 || ro.extend_from % pass_spp != 0 ||
            ro.extend_from >= ro.monte_carlo.spp) {
            Fail("--extend-from must be a multiple of --pass-spp ", pass_spp, " below --spp ",
                 ro.monte_carlo.spp, " (the earlier round's --spp), got ", ro.extend_from);
        }
    }
    const bool split = sharded || world.size > 1;
    if (split && !ro.spectral.wavelengths.empty()) {
        Fail(sharded ? "--shard" : "mpirun",
             " splits RGB renders only; --wavelengths cannot be split (yet)");
    }
    if (split && quantity != Quantity::kRadiance) {
        Fail(sharded ? "--shard" : "mpirun",
             " splits the passes of a Monte Carlo radiance render; --quantity ", ro.quantity,
             " is not one");
    }
    if (split && ro.monte_carlo.noise_flag && ro.monte_carlo.noise_flag->count() > 0) {
        Fail(sharded ? "--shard" : "mpirun",
             " splits a render of a fixed --spp; --noise (a target reached by rendering until "
             "it holds) cannot be split (`atmos merge` prints the noise reached; more paths: "
             "a later round of shards, --extend-from, docs/scale-out.md)");
    }
    if (!all_views && !sharded)
        ImageFormatFromPath(ro.output);  // fail before the work on a bad name
    // The output is writable before any work (io/output_path.h); under
    // mpirun rank 0 writes it.
    if (world.rank != 0) {
    } else if (all_views) {
        CheckOutputDirectory(ro.output);
    } else {
        CheckOutputFile(ro.output);
    }
    // A named checkpoint's directory exists and is writable (atmos creates none).
    if (!ro.checkpoint.empty()) CheckCheckpointFile(ro.checkpoint + ".bin");
    // An image written to a stream (/dev/stdout, a FIFO, /dev/null) has no
    // files beside it: no default checkpoint, no variance image.
    const bool stream_output = !all_views && IsStreamOutput(ro.output);
    if (!std::isfinite(ro.exposure) || ro.exposure < 0.0f) {
        Fail("--exposure must be a positive number");
    }
    if (!(ro.checkpoint_every >= 0.0 && ro.checkpoint_every <= 1e6)) {
        Fail("--checkpoint-every must be in [0, 1e6] seconds");
    }

    ThreadLimit limit(common.threads);
    const BackendScope backend(ParseBackend(common.backend));
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(GivenModel(common));
    RequireQuantity(model->Info(), quantity);
    if (split && !model->Info().capabilities.stochastic) {
        Fail(sharded ? "--shard" : "mpirun", " splits the passes of a Monte Carlo model; model ",
             model->Info().name, " is not one (`atmos list` marks them)");
    }
    MonteCarloSettings monte_carlo = ro.monte_carlo.Settings(model->Info());
    monte_carlo.checkpoint_seconds = ro.checkpoint_every;
    std::vector<View> views;
    if (custom) {
        views.push_back(CustomView(camera_spec, sun_direction, atmosphere));
    } else if (all_views) {
        views = StandardViews(atmosphere);
    } else {
        views.push_back(GetView(ro.view, atmosphere));
    }

    if (!ro.spectral.wavelengths.empty()) {
        if (all_views) fs::create_directories(ro.output);
        return RenderSpectralViews(common, ro, views, width, height, quantity, monte_carlo);
    }
    // Under mpirun only rank 0 reports.
    const bool quiet = common.quiet || world.rank != 0;
    const double prepare_seconds = PrepareModel(common, atmosphere, model.get());
    if (!quiet && prepare_seconds > 0.01) {
        std::fprintf(stderr, "prepared %s in %.3f s\n", common.model.c_str(), prepare_seconds);
    }

    std::vector<GalleryEntry> gallery;
    if (all_views && world.rank == 0) fs::create_directories(ro.output);
    for (const View& view : views) {
        RenderRequest request = ViewRequest(view, width, height, quantity, monte_carlo);
        request.sun_disc = ro.sun_disc;
        request.show_progress = !quiet;
        MonteCarloShard shard;
        shard.index = sharded ? shard_index : world.rank;
        shard.count = sharded ? shard_count : world.size;
        if (ro.extend_from > 0) shard.first_pass = ro.extend_from / ro.monte_carlo.pass_spp;
        const ShardScope shard_scope(split ? &shard : nullptr);
        const bool stochastic = model->Info().capabilities.stochastic;
        Image variance;
        MonteCarloReport report;
        request.report = &report;
        std::string out_stem = fs::path(ro.output).replace_extension().string();
        if (all_views) {
            out_stem = (fs::path(ro.output) / (common.model + "-" + view.name)).string();
        }
        if (stochastic && quantity == Quantity::kRadiance) {
            request.checkpoint = ro.checkpoint.empty() ? out_stem + ".ckpt"
                                 : all_views           ? ro.checkpoint + "-" + view.name
                                                       : ro.checkpoint;
            // Under mpirun each rank checkpoints its own passes.
            if (world.size > 1) {
                request.checkpoint +=
                    ".rank-" + std::to_string(world.rank + 1) + "-of-" + std::to_string(world.size);
            }
            request.resume = ro.resume;
            if (!stream_output) request.variance = &variance;
            if (stream_output && ro.checkpoint.empty()) request.checkpoint.clear();
        }
        Image image;
        const auto start = std::chrono::steady_clock::now();
        model->Render(request, &image);
        double seconds = Seconds(start);
        const float exposure = ro.exposure > 0.0f                ? ro.exposure
                               : quantity == Quantity::kRadiance ? view.exposure
                                                                 : 1.0f;
        auto drop_checkpoint = [&]() {
            // The output is written: its checkpoint has done its job (issue 18 item 10).
            if (!request.checkpoint.empty() && !ro.keep_checkpoint) {
                std::error_code ignored;
                fs::remove(request.checkpoint + ".bin", ignored);
            }
        };
        if (sharded) {
            // The shard's passes and the render's fingerprint (render/shards.h).
            ShardFile file;
            file.shard = std::move(shard);
            nlohmann::json extra;
            extra["view"] = view.name;
            extra["exposure"] = exposure;
            extra["seconds"] = seconds;
            file.extra = extra.dump();
            WriteFileAtomically(ro.output, SerializeShardFile(file));
            drop_checkpoint();
            if (!quiet) {
                std::fprintf(stderr,
                             "rendered shard %s of %-22s %dx%d with %s (%zu of %lld passes) in "
                             "%.3f s (%d threads)\n",
                             ro.shard.c_str(), view.name.c_str(), width, height,
                             common.model.c_str(), file.shard.pass_images.size(),
                             static_cast<long long>(file.shard.passes), seconds,
                             ParallelThreadCount());
            }
            continue;
        }
        if (world.size > 1) {
            // Every rank's passes to rank 0, merged there in pass order.
            std::vector<MonteCarloShard> shards = GatherShards(std::move(shard));
            drop_checkpoint();
            if (world.rank != 0) continue;
            std::vector<ShardFile> files(shards.size());
            std::vector<std::string> names;
            for (size_t r = 0; r < shards.size(); ++r) {
                files[r].shard = std::move(shards[r]);
                names.push_back("rank " + std::to_string(r));
            }
            MergeShards(files, names, &image, request.variance, &report);
            seconds = Seconds(start);
        }
        if (all_views) {
            const std::string stem = common.model + "-" + view.name;
            WriteImage(image, (fs::path(ro.output) / (stem + ".png")).string(), exposure);
            WriteImage(image, (fs::path(ro.output) / (stem + ".exr")).string(), exposure);
            gallery.push_back(
                {view.name, view.description, stem + ".png", stem + ".exr", seconds, exposure});
        } else {
            WriteImage(image, ro.output, exposure);
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
            std::fprintf(stderr, "rendered %-22s %dx%d with %s in %.3f s (%d threads%s)\n",
                         view.name.c_str(), width, height, common.model.c_str(), seconds,
                         ParallelThreadCount(),
                         world.size > 1
                             ? (" per rank, " + std::to_string(world.size) + " MPI ranks").c_str()
                             : "");
        }
    }
    if (all_views && world.rank == 0) {
        const ModelInfo& info = model->Info();
        const std::string page = (fs::path(ro.output) / "index.html").string();
        WriteGalleryHtml(page, "atmos: " + info.title,
                         "model " + info.name + " (" + info.citation + "), atmosphere " +
                             common.atmosphere + ", " + ro.size + ", " + ro.quantity +
                             "; PNG: exposure, 1 - exp(-x), sRGB",
                         gallery);
        if (!quiet) std::fprintf(stderr, "wrote %s\n", page.c_str());
    }
    return 0;
}

}  // namespace

Command AddRenderCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto ro = std::make_shared<RenderOptions>();
    Command c;
    CLI::App* render = root->add_subcommand("render", "render one view (or all) with one model");
    AddCommonOptions(render, common.get());
    AddBackendOption(render, &common->backend);
    render->add_option("--view,-v", ro->view, "view name, or 'all' (-o is then a directory)")
        ->capture_default_str()
        ->each([ro](const std::string&) { ro->view_given = true; });
    render->add_option("--camera", ro->camera,
                       "a free camera instead of --view: KEY=VALUE[,...] with altitude (m above "
                       "the ground), azimuth (deg clockwise from north), elevation, roll, fov "
                       "(vertical, deg), projection=perspective|equirect (2:1)|fisheye|cubemap "
                       "(6:1 strip +X,-X,+Y,-Y,+Z,-Z)|equal-area (square, pbrt-v4); default "
                       "perspective at the ground looking north at the horizon, fov 60 "
                       "(docs/views.md); needs --sun");
    render->add_option("--sun", ro->sun,
                       "the sun for --camera: elevation=DEG[,azimuth=DEG] (azimuth clockwise from "
                       "north, default 0) or time=ISO-8601,latitude=DEG,longitude=DEG (NREL SPA; "
                       "docs/sun.md); radiance is then per unit solar irradiance times the "
                       "atmosphere's solar_irradiance");
    render->add_option("--size,-s", ro->size, "image size WIDTHxHEIGHT")->capture_default_str();
    render->add_option("--quantity", ro->quantity, "radiance or transmittance")
        ->capture_default_str();
    render->add_flag("--sun-disc", ro->sun_disc, "add the sun's disc");
    render->add_option("--exposure", ro->exposure, "PNG exposure (default: the view's)");
    render->add_option("-o,--output", ro->output,
                       "output file (.exr .png .npy .pfm), or directory with --view all");
    render->add_option("--checkpoint", ro->checkpoint,
                       "Monte Carlo models: checkpoint file stem (default: OUTPUT without its "
                       "extension + .ckpt); checkpoints hold the sums and the sample count");
    render->add_flag("--keep-checkpoint", ro->keep_checkpoint,
                     "Monte Carlo models: keep the checkpoint after the image is written (to "
                     "extend the render later with a larger --spp and --resume); by default it "
                     "is deleted");
    render
        ->add_option("--checkpoint-every", ro->checkpoint_every,
                     "Monte Carlo models: the longest time between checkpoints, in seconds "
                     "(passes are rendered in bands of rows of about a second, so this holds "
                     "inside long passes too; 0: after every band of one row)")
        ->capture_default_str();
    render->add_flag("--resume", ro->resume,
                     "Monte Carlo models: continue from the checkpoint of the same render");
    render->add_option("--shard", ro->shard,
                       "Monte Carlo models: render only shard K of N (K/N: the passes p with p "
                       "mod N = K - 1) and write its passes to -o FILE.shard; `atmos merge` "
                       "makes the image one process would have made (docs/scale-out.md)");
    render->add_option("--extend-from", ro->extend_from,
                       "with --shard: a later round, only the passes after the first SPP paths "
                       "per pixel (an earlier round's --spp, a multiple of --pass-spp); merge "
                       "it with the earlier round's shards");
    AddMonteCarloFlags(render, &ro->monte_carlo, true);
    AddSpectralFlags(render, &ro->spectral);
    c.app = render;
    c.run = [common, ro] { return CmdRender(*common, *ro); };
    return c;
}

}  // namespace atmos::cli
