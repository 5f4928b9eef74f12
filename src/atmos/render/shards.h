// atmos: shards of a Monte Carlo render and their merge (issue 36).
//
// A render of P passes (render/progressive.h) is split into N shards: shard K
// (0-based here, K/N counted from 1 on the command line) holds the passes p
// with p % N == K. Each shard keeps every pass's mean image as it is, not a
// partial sum: float addition is not associative, so partial sums of shards
// cannot be added up to the one process's sums bit for bit. MergeShards loads
// all the shards, checks that they share one fingerprint and hold every pass
// exactly once, and then adds the passes in pass order through the one
// function the one-process render adds them with (AccumulatePass): the image
// and its variance are the one process's, byte for byte, for any N and in
// whatever order the shards are given.
//
// A shard file (also a shard's checkpoint, STEM.bin) is one binary file:
//   "atmossh1", the header's length (uint64, host byte order), the header
//   (JSON: format "atmos-shard-1", fingerprint, shard [index, count],
//   passes, width, height, pass_list [[pass, samples], ...], for a checkpoint
//   `partial` {pass, samples, rows_done}, and `extra`, informational), the
//   pass images (float32, width x height x 3 each, in pass_list order, then
//   the partial pass's image), and a 64-bit FNV-1a checksum of everything
//   before it. One file per shard (written atomically) so a copy between
//   machines is one file, the float32 bits travel exactly (no image codec in
//   between), and a truncated or damaged copy is refused by its checksum.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "atmos/image.h"
#include "atmos/model.h"

namespace atmos {

// One pass of a Monte Carlo render as a shard keeps it: its index in the
// render (0-based), its paths per pixel and the pass's mean image.
struct MonteCarloPassImage {
    int64_t index = 0;
    int64_t samples = 0;
    Image mean;
};

// A shard of a Monte Carlo render (issue 36): the passes p with
// p % count == index (index in [0, count)). While a ShardScope names one on
// the calling thread, a Monte Carlo radiance render renders only those passes
// and leaves them here, with the render's fingerprint (JSON text: everything
// that fixes its passes, the same for every shard of one render), instead of
// the image (left empty; no noise target; its checkpoint then holds the
// shard's passes). MergeShards (render/shards.h) makes the image one process
// would have rendered.
struct MonteCarloShard {
    int64_t index = 0;
    int64_t count = 1;
    // A later round (extending a render that stopped at first_pass passes):
    // the shard holds the passes p >= first_pass with
    // (p - first_pass) % count == index.
    int64_t first_pass = 0;
    // Filled by the render:
    std::string fingerprint;  // without spp: rounds of one render share it
    int64_t spp = 0;          // paths per pixel of the render the shard belongs to
    int64_t passes = 0;       // passes of that render
    int width = 0;
    int height = 0;
    std::vector<MonteCarloPassImage> pass_images;  // in pass order
};

// Renders on this thread render `shard` (above) for the scope's life. A scope
// rather than a RenderRequest field: the public request (atmos/model.h) stays
// as it was; the CLI's `render --shard` and its MPI ranks set it.
class ShardScope {
  public:
    explicit ShardScope(MonteCarloShard* shard);
    ~ShardScope();
    ShardScope(const ShardScope&) = delete;
    ShardScope& operator=(const ShardScope&) = delete;

  private:
    MonteCarloShard* previous_;
};

// Defined in render/progressive.cpp, used by the render and by MergeShards:
// adds one pass's mean `v` (`count` floats) weighted by its paths per pixel to
// the sums: sum += w v, sum_sq += w v v, and sum_even += w v unless it is
// null. The one place a pass enters the sums, in a render and in a merge of
// its shards (render/shards.h), so that both do the same float operations in
// the same order.
void AccumulatePass(float* sum, float* sum_sq, float* sum_even, const float* v, size_t count,
                    float weight);
// Defined in render/progressive.cpp: the image (out, already sized as the sums) and, where given,
// the variance of its mean (batch means over the passes) from the sums of `passes_done` passes of
// `samples_done` paths per pixel in all.
void FinishMonteCarlo(const Image& sum, const Image& sum_sq, int64_t samples_done,
                      int64_t passes_done, Image* out, Image* variance);

// The shard the innermost ShardScope on this thread names (null: none).
MonteCarloShard* CurrentShard();

struct ShardFile {
    MonteCarloShard shard;
    // A checkpoint of a shard in progress: rows [0, rows_done) of pass
    // partial.index (partial.samples paths) are done (rows_done 0: none).
    MonteCarloPassImage partial;
    int rows_done = 0;
    std::string extra = "{}";  // JSON object text, informational (e.g. the view's exposure)
};

// The file's bytes.
std::string SerializeShardFile(const ShardFile& file);
// Parses and verifies a shard file's bytes (magic, checksum, header, sizes,
// the pass list against the fingerprint's spp and pass size, finite and
// non-negative values): one atmos::Error naming `what` otherwise.
ShardFile ParseShardFile(const std::string& bytes, const std::string& what);
// Reads a shard file: a regular file, then ParseShardFile.
ShardFile ReadShardFile(const std::string& path);

// The passes of a render of `passes` passes that shard `index` of `count` holds
// (of the passes from first_pass on).
std::vector<int64_t> ShardPasses(int64_t passes, int64_t index, int64_t count,
                                 int64_t first_pass = 0);

// Merges finished shards (names[i] names files[i] in messages) into the render
// of the largest spp among them (shards of a render of fewer paths, a first
// round, stand for its passes when they are whole passes of the larger one):
// one atmos::Error, before anything is computed, when a shard is unfinished,
// from another render (its fingerprint differs: the fields that differ are
// named; or its passes are not the larger render's), or when a pass is
// missing or held twice. Then the image (and, where given,
// the variance of its mean) exactly as the one-process render makes them;
// report->samples gets the paths per pixel and report->noise the HDR-FLIP
// between the means of the even and the odd passes (the measure of a noise
// target; -1 with one pass) and report->noise_map its per-pixel map.
void MergeShards(const std::vector<ShardFile>& files, const std::vector<std::string>& names,
                 Image* out, Image* variance, MonteCarloReport* report);

}  // namespace atmos
