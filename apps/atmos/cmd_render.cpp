// atmos CLI: `atmos render`.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "harness/mpi_world.h"
#include "harness/render_run.h"

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
    RenderRun run;
    run.model = common.model;
    run.output = ro.output;
    run.all_views = all_views;
    run.width = width;
    run.height = height;
    run.quantity = quantity;
    run.sun_disc = ro.sun_disc;
    run.exposure = ro.exposure;
    run.quiet = common.quiet;
    run.checkpoint = ro.checkpoint;
    run.resume = ro.resume;
    run.keep_checkpoint = ro.keep_checkpoint;
    run.pass_spp = ro.monte_carlo.pass_spp;
    run.gather = GatherShards;
    run.atmosphere = common.atmosphere;
    run.size = ro.size;
    run.quantity_name = ro.quantity;
    // --shard K/N (or the ranks of mpirun): the passes of one Monte Carlo
    // radiance render, split (harness/render_split.h).
    const MpiWorld& world = World();
    run.split.shard = ro.shard;
    run.split.extend_from = ro.extend_from;
    run.split.world_rank = world.rank;
    run.split.world_size = world.size;
    const bool noise = ro.monte_carlo.noise_flag && ro.monte_carlo.noise_flag->count() > 0;
    CheckRenderSplit(&run.split, {ro.output, all_views, !ro.spectral.wavelengths.empty(), quantity,
                                  ro.quantity, ro.monte_carlo.spp, ro.monte_carlo.pass_spp, noise});
    CheckRenderRun(run, ro.checkpoint_every);
    CheckSpectralFlagsNeedWavelengths(ro.spectral);

    ThreadLimit limit(common.threads);
    const BackendScope backend(ParseBackend(common.backend));
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(GivenModel(common));
    RequireQuantity(model->Info(), quantity);
    CheckRenderSplitModel(run.split, model->Info());
    run.monte_carlo = ro.monte_carlo.Settings(model->Info());
    if (!model->Info().capabilities.stochastic &&
        (ro.resume || ro.keep_checkpoint || !ro.checkpoint.empty())) {
        Fail(
            "--checkpoint, --resume and --keep-checkpoint apply to Monte Carlo models only; "
            "model ",
            model->Info().name, " is not one (`atmos list` marks them)");
    }
    run.monte_carlo.checkpoint_seconds = ro.checkpoint_every;
    std::vector<View> views;
    if (custom) {
        views.push_back(CustomView(camera_spec, sun_direction, atmosphere));
    } else if (all_views) {
        views = StandardViews(atmosphere);
    } else {
        views.push_back(GetView(ro.view, atmosphere));
    }
    if (!ro.spectral.wavelengths.empty()) {
        const SpectralFlags& f = ro.spectral;
        RenderSpectralViews(
            run, GivenModel(common),
            {f.wavelengths, f.colour, f.white, f.batch_seeds, f.batch_layout, common.atmosphere,
             common.sets, !common.load.empty(), f.channel_batches, CliWidePrepare(common)},
            views, [&](const AtmosphereParameters& a, Model* m) { PrepareModel(common, a, m); });
        return 0;
    }
    // Under mpirun only rank 0 reports.
    const bool quiet = common.quiet || world.rank != 0;
    const double prepare_seconds = PrepareModel(common, atmosphere, model.get());
    if (!quiet && prepare_seconds > 0.01) {
        std::fprintf(stderr, "prepared %s in %.3f s\n", common.model.c_str(), prepare_seconds);
    }
    run.quiet = quiet;
    RenderViews(run, model.get(), views);
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
