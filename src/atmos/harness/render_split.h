// atmos: how one `atmos render` is split over processes (issue 36), and the
// merge of the pieces: the policy of `render --shard K/N`, `--extend-from`,
// `mpirun -np N atmos render` and `atmos merge`, testable in-process (the CLI
// only maps its flags onto these). The shards themselves: render/shards.h; MPI:
// harness/mpi_world.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "atmos/image.h"
#include "atmos/model.h"
#include "render/shards.h"

namespace atmos {

// --shard K/N: *index = K - 1 and *count = N for 1 <= K <= N <= 1000000; one
// atmos::Error naming the flag otherwise.
void ParseShardSpec(const std::string& text, int64_t* index, int64_t* count);

// The split of one render: a shard (--shard K/N, or none), a later round
// (--extend-from SPP) and the MPI world the process runs in.
struct RenderSplit {
    std::string shard;        // --shard K/N as given; empty: no shard
    int64_t extend_from = 0;  // --extend-from SPP (0: the first round)
    int world_rank = 0;
    int world_size = 1;
    // Set by CheckRenderSplit from `shard`:
    int64_t shard_index = 0;
    int64_t shard_count = 1;

    bool sharded() const { return !shard.empty(); }
    bool split() const { return sharded() || world_size > 1; }
};

// What the split render is: its output, views, quantity and Monte Carlo flags.
struct RenderSplitTarget {
    std::string output;
    bool all_views = false;
    bool spectral = false;  // --wavelengths given
    Quantity quantity = Quantity::kRadiance;
    std::string quantity_name;  // as given, for messages
    int64_t spp = 0;
    int64_t pass_spp = 0;
    bool noise_target = false;  // --noise given
};

// Parses split->shard and refuses a split the render cannot make (one
// atmos::Error naming the flag): a shard under mpirun, of --view all, written
// elsewhere than to FILE.shard (or a stream); a .shard output without --shard;
// --extend-from without --shard, --pass-spp, or not a multiple of it below
// --spp; a split of a spectral, non-radiance or --noise render.
void CheckRenderSplit(RenderSplit* split, const RenderSplitTarget& target);
// A split render's model is a Monte Carlo one (one atmos::Error otherwise).
void CheckRenderSplitModel(const RenderSplit& split, const ModelInfo& info);
// The shard this process renders (its shard, or its rank's under MPI).
MonteCarloShard RenderSplitShard(const RenderSplit& split, int64_t pass_spp);

// Writes a rendered shard to `path` (render/shards.h's file; `extra` records
// the view, its exposure and the seconds it took); *shard is left as it was.
void WriteRenderShard(const std::string& path, MonteCarloShard* shard, const std::string& view,
                      float exposure, double seconds);
// Merges the ranks' shards (rank order) into the image, variance and report
// the one-process render makes (MergeShards).
void MergeRankShards(std::vector<MonteCarloShard> shards, Image* image, Image* variance,
                     MonteCarloReport* report);

// `atmos merge PARTS... -o OUTPUT`: checks, reads the shard files, merges them
// and writes the image and OUTPUT's STEM.variance.exr (unless a stream);
// exposure 0: the one the render recorded. Prints a summary unless quiet.
void MergeShardFilesToImage(const std::vector<std::string>& parts, const std::string& output,
                            float exposure, bool quiet);

}  // namespace atmos
