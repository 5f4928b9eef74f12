// The policy of a split render (harness/render_split.h, harness/render_run.h):
// `render --shard K/N`, `--extend-from`, mpirun's ranks and `atmos merge`,
// checked in-process: the accepted splits, the shard each process renders,
// and every refusal's one message (the CLI prints it as `atmos: error: ...`).
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>

#include "atmos/error.h"
#include "atmos/model.h"
#include "harness/render_run.h"
#include "harness/render_split.h"
#include "test_util.h"

namespace atmos {
namespace {

using atmos_test::ErrorOrEmpty;

TEST(RenderSplit, ParsesShardKOfN) {
    int64_t index = -1, count = -1;
    ParseShardSpec("2/8", &index, &count);
    EXPECT_EQ(index, 1);
    EXPECT_EQ(count, 8);
    ParseShardSpec("1/1", &index, &count);
    EXPECT_EQ(index, 0);
    EXPECT_EQ(count, 1);
    ParseShardSpec("1000000/1000000", &index, &count);
    EXPECT_EQ(index, 999999);
    EXPECT_EQ(count, 1000000);
}

TEST(RenderSplit, RefusesMalformedShards) {
    for (const char* text : {"", "2", "/8", "2/", "0/8", "9/8", "-1/8", "2/0", "a/8", "2/b", "2/8x",
                             "2x/8", "1/1000001", "1/2/3", "2.0/8", "99999999999999999999/8"}) {
        int64_t index = 0, count = 0;
        EXPECT_EQ(ErrorOrEmpty([&] { ParseShardSpec(text, &index, &count); }),
                  std::string("--shard must be K/N with 1 <= K <= N <= 1000000 (shard K of N, "
                              "e.g. 2/8), got '") +
                      text + "'")
            << text;
    }
}

// A sharded radiance render of one view to a .shard file: accepted.
RenderSplitTarget ShardTarget() {
    RenderSplitTarget t;
    t.output = "out/part-2.shard";
    t.quantity_name = "radiance";
    t.spp = 64;
    t.pass_spp = 8;
    return t;
}

RenderSplit Shard(const std::string& text, int64_t extend_from = 0) {
    RenderSplit split;
    split.shard = text;
    split.extend_from = extend_from;
    return split;
}

TEST(RenderSplit, AcceptsShardsAndRoundsAndGivesTheirPasses) {
    RenderSplit split = Shard("3/4", 16);
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplit(&split, ShardTarget()); }), "");
    EXPECT_TRUE(split.sharded());
    EXPECT_TRUE(split.split());
    const MonteCarloShard shard = RenderSplitShard(split, 8);
    EXPECT_EQ(shard.index, 2);
    EXPECT_EQ(shard.count, 4);
    EXPECT_EQ(shard.first_pass, 2);  // 16 paths per pixel in passes of 8
    // A shard to a stream (no .shard name) is accepted too.
    RenderSplitTarget stream = ShardTarget();
    stream.output = "/dev/stdout";
    split = Shard("1/2");
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplit(&split, stream); }), "");
}

TEST(RenderSplit, MpiRanksAreTheShards) {
    RenderSplit split;
    split.world_rank = 2;
    split.world_size = 3;
    RenderSplitTarget target = ShardTarget();
    target.output = "sky.exr";
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplit(&split, target); }), "");
    EXPECT_FALSE(split.sharded());
    EXPECT_TRUE(split.split());
    const MonteCarloShard shard = RenderSplitShard(split, 8);
    EXPECT_EQ(shard.index, 2);
    EXPECT_EQ(shard.count, 3);
    EXPECT_EQ(shard.first_pass, 0);
    // One process, no shard: no split, and nothing refused for it.
    RenderSplit none;
    target.quantity = Quantity::kTransmittance;
    target.spectral = true;
    target.noise_target = true;
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplit(&none, target); }), "");
    EXPECT_FALSE(none.split());
}

TEST(RenderSplit, RefusesSplitsTheRenderCannotMake) {
    auto refusal = [](RenderSplit split, const RenderSplitTarget& target) {
        return ErrorOrEmpty([&] { CheckRenderSplit(&split, target); });
    };
    RenderSplit mpi = Shard("1/2");
    mpi.world_size = 2;
    EXPECT_EQ(refusal(mpi, ShardTarget()),
              "--shard cannot be combined with mpirun (the ranks are the shards)");
    RenderSplitTarget t = ShardTarget();
    t.all_views = true;
    EXPECT_EQ(refusal(Shard("1/2"), t),
              "--shard renders one view: give --view NAME, not --view all");
    t = ShardTarget();
    t.output = "sky.exr";
    EXPECT_EQ(refusal(Shard("1/2"), t),
              "--shard writes the shard's passes, not an image: -o must end in .shard (got "
              "'sky.exr'); `atmos merge` makes the image");
    t = ShardTarget();
    EXPECT_EQ(refusal(RenderSplit(), t), "-o out/part-2.shard: a .shard output needs --shard K/N");
    t.output = "sky.exr";
    EXPECT_EQ(refusal(Shard("", 16), t),
              "--extend-from needs --shard K/N (a later round of shards)");
    t = ShardTarget();
    t.pass_spp = 0;
    EXPECT_EQ(refusal(Shard("1/2", 16), t),
              "--extend-from needs --pass-spp P (the same in every round: it fixes the passes)");
    const std::string multiple =
        "--extend-from must be a multiple of --pass-spp 8 below --spp 64 (the earlier round's "
        "--spp), got ";
    for (int64_t e : {12, 64, 72, -8}) {
        EXPECT_EQ(refusal(Shard("1/2", e), ShardTarget()), multiple + std::to_string(e)) << e;
    }
    // The same refusals name the splitter: --shard, or mpirun.
    RenderSplit ranks;
    ranks.world_size = 4;
    t = ShardTarget();
    t.spectral = true;
    EXPECT_EQ(refusal(Shard("1/2"), t),
              "--shard splits RGB renders only; --wavelengths cannot be split (yet)");
    t.output = "sky.exr";
    EXPECT_EQ(refusal(ranks, t),
              "mpirun splits RGB renders only; --wavelengths cannot be split (yet)");
    t = ShardTarget();
    t.quantity = Quantity::kTransmittance;
    t.quantity_name = "transmittance";
    EXPECT_EQ(refusal(Shard("1/2"), t),
              "--shard splits the passes of a Monte Carlo radiance render; --quantity "
              "transmittance is not one");
    t = ShardTarget();
    t.noise_target = true;
    t.output = "sky.exr";
    EXPECT_EQ(refusal(ranks, t),
              "mpirun splits a render of a fixed --spp; --noise (a target reached by rendering "
              "until it holds) cannot be split (`atmos merge` prints the noise reached; more "
              "paths: a later round of shards, --extend-from, docs/scale-out.md)");
}

TEST(RenderSplit, RefusesADeterministicModel) {
    ModelInfo info;
    info.name = "naive";
    info.capabilities.stochastic = false;
    RenderSplit split = Shard("1/2");
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplitModel(split, info); }),
              "--shard splits the passes of a Monte Carlo model; model naive is not one (`atmos "
              "list` marks them)");
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplitModel(RenderSplit(), info); }), "");
    info.capabilities.stochastic = true;
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderSplitModel(split, info); }), "");
}

TEST(RenderSplit, MergeRefusesBeforeReadingAnything) {
    EXPECT_EQ(ErrorOrEmpty([] { MergeShardFilesToImage({"a.shard"}, "", 0.0f, true); }),
              "merge needs an output: -o FILE (.exr .png .npy .pfm)");
    EXPECT_EQ(ErrorOrEmpty([] { MergeShardFilesToImage({}, "sky.exr", 0.0f, true); }),
              "merge needs the shards: atmos merge PART.shard... -o FILE");
    EXPECT_EQ(ErrorOrEmpty([] { MergeShardFilesToImage({"a.shard"}, "sky.exr", -1.0f, true); }),
              "--exposure must be a positive number");
}

TEST(RenderRun, RefusesBadExposureAndCheckpointInterval) {
    const std::filesystem::path dir = std::filesystem::path(ATMOS_TEST_TMP) / "render_run";
    std::filesystem::create_directories(dir);
    RenderRun run;
    run.output = (dir / "sky.xyz").string();
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderRun(run, 10.0); }),
              "cannot tell the image format of '" + run.output +
                  "': unknown extension '.xyz' (allowed: .exr .png .npy .pfm)");
    run.output = (dir / "sky.exr").string();
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderRun(run, 10.0); }), "");
    run.output = (dir / "missing" / "sky.exr").string();
    EXPECT_NE(ErrorOrEmpty([&] { CheckRenderRun(run, 10.0); }), "");
    run.split.world_rank = 1;  // under mpirun rank 0 writes the output
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderRun(run, 10.0); }), "");
    run.output = (dir / "sky.exr").string();
    run.split.world_rank = 0;
    run.exposure = -1.0f;
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderRun(run, 10.0); }),
              "--exposure must be a positive number");
    run.exposure = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderRun(run, 10.0); }),
              "--exposure must be a positive number");
    run.exposure = 0.0f;
    for (double every : {-1.0, 2e6, std::numeric_limits<double>::quiet_NaN()}) {
        EXPECT_EQ(ErrorOrEmpty([&] { CheckRenderRun(run, every); }),
                  "--checkpoint-every must be in [0, 1e6] seconds")
            << every;
    }
}

}  // namespace
}  // namespace atmos
