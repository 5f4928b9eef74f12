// atmos: the work of `atmos render` once its flags are checked: the views
// rendered with one model and written (images, variance, checkpoints, shard
// files, the gallery of --view all), RGB or spectral. The CLI maps its flags
// onto a RenderRun; the split over shards and MPI ranks is
// harness/render_split.h.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "atmos/model.h"
#include "atmos/view.h"
#include "harness/render_split.h"
#include "harness/spectral_run.h"

namespace atmos {

// The request of one view at a size and quantity with Monte Carlo settings, no
// progress bar (callers set the rest).
RenderRequest ViewRequest(const View& view, int width, int height, Quantity quantity,
                          const MonteCarloSettings& monte_carlo);

struct RenderRun {
    std::string model;   // --model as given: in file names and messages
    std::string output;  // a file, or the directory of --view all
    bool all_views = false;
    int width = 0;
    int height = 0;
    Quantity quantity = Quantity::kRadiance;
    MonteCarloSettings monte_carlo;
    bool sun_disc = false;
    float exposure = 0.0f;  // 0: the view's
    bool quiet = false;
    // Monte Carlo radiance: the checkpoint stem (empty: OUTPUT's stem + .ckpt),
    // --resume, --keep-checkpoint.
    std::string checkpoint;
    bool resume = false;
    bool keep_checkpoint = false;
    RenderSplit split;  // checked (CheckRenderSplit)
    int64_t pass_spp = 0;
    // Under mpirun: every rank's shard at rank 0 (harness/mpi_world.h GatherShards).
    std::function<std::vector<MonteCarloShard>(MonteCarloShard)> gather;
    // The gallery's caption (--view all).
    std::string atmosphere;
    std::string size;
    std::string quantity_name;
};

// Before any work: the output's name and that it can be written (rank 0's
// under MPI), a named checkpoint's directory, --exposure and
// --checkpoint-every (seconds); one atmos::Error naming the flag otherwise.
void CheckRenderRun(const RenderRun& run, double checkpoint_every);

// Renders `views` with the prepared `model` and writes them: the image (or
// the shard file), STEM.variance.exr, and for --view all OUTPUT/MODEL-VIEW.png
// and .exr and OUTPUT/index.html.
void RenderViews(const RenderRun& run, Model* model, const std::vector<View>& views);

// The spectral flags of a render (--wavelengths, --colour, --white,
// --batch-seeds, --batch-layout) and where the atmosphere comes from.
struct SpectralRenderFlags {
    std::string wavelengths;
    std::string colour;
    std::string white;
    std::string batch_seeds;
    std::string batch_layout;
    std::string atmosphere;
    std::vector<std::string> sets;
    bool load = false;                     // --load given (refused)
    std::string channel_batches = "wide";  // --channel-batches
    WidePrepareFunction prepare_wide;      // SpectralBatching::prepare_wide
};

// --wavelengths: the views rendered at each wavelength (harness/spectral_run.h);
// OUTPUT gets the colour (--colour, --white), STEM.spectral.exr the spectrum.
void RenderSpectralViews(const RenderRun& run, const ModelSpec& spec,
                         const SpectralRenderFlags& flags, const std::vector<View>& views,
                         const PrepareFunction& prepare);

}  // namespace atmos
