// Shards of a Monte Carlo render and their merge (issue 36, render/shards.h):
// the merged image and variance are the one-process render's, byte for byte,
// for any number of shards given in any order; a merge refuses a missing,
// duplicated, foreign or unfinished shard; a shard interrupted and resumed
// holds the same passes; and the same through the command line
// (`render --shard K/N`, `atmos merge`) with the path tracer.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "base/progress.h"
#include "base/rng.h"
#include "metrics/flip.h"
#include "render/progressive.h"
#include "render/shards.h"
#include "test_util.h"

namespace atmos {
namespace {

namespace fs = std::filesystem;

// A test-only Monte Carlo model: pixel (x, y), channel c of a pass is the mean
// of the pass's samples of Rng(seed, pixel, sample)'s c-th uniform, squared
// (so that the sums of squares are not trivial). RenderPass can be made to
// throw at a given band (an interruption).
class DiceModel : public MonteCarloModel {
  public:
    DiceModel() {
        info_.name = "dice";
        info_.capabilities.stochastic = true;
    }
    const ModelInfo& Info() const override { return info_; }
    void Prepare(const AtmosphereParameters&) override {}
    void RenderPass(const RenderRequest& request, const MonteCarloPass& pass, Image* out,
                    Progress* progress) const override {
        if (bands == fail_at_band) throw Error("dice: an injected failure");
        ++bands;
        const int rows = pass.rows > 0 ? pass.rows : request.height - pass.row_begin;
        out->Resize(request.width, rows);
        for (int y = 0; y < rows; ++y) {
            for (int x = 0; x < request.width; ++x) {
                const uint64_t key =
                    static_cast<uint64_t>((pass.row_begin + y) * request.width + x);
                Vec3d sum(0.0);
                for (int64_t s = pass.first_sample; s < pass.first_sample + pass.samples; ++s) {
                    Rng rng(pass.seed, key, static_cast<uint64_t>(s));
                    for (int c = 0; c < 3; ++c) {
                        const double u = rng.Uniform();
                        sum[c] += u * u * 3.7;
                    }
                }
                out->Set(x, y, Rgb(sum / static_cast<double>(pass.samples)));
            }
        }
        if (progress) progress->Add(static_cast<int64_t>(request.width) * rows);
    }
    std::vector<SampleAnswer> SamplePass(const std::vector<SampleQuery>& queries,
                                         const MonteCarloPass&) const override {
        return std::vector<SampleAnswer>(queries.size());
    }
    std::string PassKey() const override { return "{\"dice\": 1}"; }

    mutable int bands = 0;
    mutable int fail_at_band = -1;

  private:
    ModelInfo info_;
};

RenderRequest DiceRequest(int64_t spp, int64_t pass_spp, uint64_t seed = 5) {
    return atmos_test::MonteCarloRequest(GetView("ground-noon", EarthAtmosphere()), 7, 4, spp,
                                         pass_spp, seed);
}

fs::path TestDir(const char* name) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    const fs::path dir =
        (env ? fs::path(env) : fs::temp_directory_path() / "atmos_test") / "shards" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

bool SameBytes(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Shard `index` of `count` of `request`, as a file would hold it.
ShardFile RenderShard(const Model& model, RenderRequest request, int64_t index, int64_t count,
                      int64_t first_pass = 0) {
    ShardFile file;
    file.shard.index = index;
    file.shard.count = count;
    file.shard.first_pass = first_pass;
    {
        const ShardScope scope(&file.shard);
        Image ignored;
        model.Render(request, &ignored);
        EXPECT_TRUE(ignored.empty());
    }
    // Through the file format, as `atmos merge` reads it.
    return ParseShardFile(SerializeShardFile(file), "test shard");
}

std::string MergeError(const std::vector<ShardFile>& files) {
    std::vector<std::string> names;
    for (size_t i = 0; i < files.size(); ++i) names.push_back("part" + std::to_string(i));
    Image image, variance;
    try {
        MergeShards(files, names, &image, &variance, nullptr);
    } catch (const Error& e) {
        EXPECT_TRUE(image.empty());  // nothing made
        return e.what();
    }
    return "";
}

TEST(Shards, MergedShardsAreTheOneProcessRenderForAnyCount) {
    const DiceModel model;
    // 11 passes of 3 paths and a last one of 2: a short last pass too.
    RenderRequest request = DiceRequest(35, 3);
    Image one, one_variance;
    request.variance = &one_variance;
    model.Render(request, &one);
    request.variance = nullptr;
    for (int64_t count : {1, 2, 3, 5, 12, 15}) {
        std::vector<ShardFile> files;
        for (int64_t k = 0; k < count; ++k) files.push_back(RenderShard(model, request, k, count));
        // Any order of the shards: reversed here.
        std::reverse(files.begin(), files.end());
        std::vector<std::string> names(files.size(), "part");
        Image merged, variance;
        MonteCarloReport report;
        MergeShards(files, names, &merged, &variance, &report);
        EXPECT_TRUE(SameBytes(merged, one)) << count << " shards";
        EXPECT_TRUE(SameBytes(variance, one_variance)) << count << " shards";
        EXPECT_EQ(report.samples, 35);
        // The noise: the HDR-FLIP between the even and the odd passes' means,
        // here from the passes' images directly (in double).
        std::vector<double> even(one.size(), 0.0), odd(one.size(), 0.0);
        double even_w = 0.0, odd_w = 0.0;
        for (const ShardFile& f : files) {
            for (const MonteCarloPassImage& p : f.shard.pass_images) {
                std::vector<double>& half = p.index % 2 == 0 ? even : odd;
                (p.index % 2 == 0 ? even_w : odd_w) += static_cast<double>(p.samples);
                for (size_t i = 0; i < one.size(); ++i) {
                    half[i] +=
                        static_cast<double>(p.samples) * static_cast<double>(p.mean.data()[i]);
                }
            }
        }
        Image a(one.width(), one.height()), b(one.width(), one.height());
        for (size_t i = 0; i < one.size(); ++i) {
            a.data()[i] = static_cast<float>(even[i] / even_w);
            b.data()[i] = static_cast<float>(odd[i] / odd_w);
        }
        EXPECT_NEAR(report.noise, HdrFlip(a, b).mean, 1e-4) << count << " shards";
        EXPECT_GT(report.noise, 0.0);
    }
}

TEST(Shards, MergeRefusesMissingDuplicateForeignAndUnfinishedShards) {
    const DiceModel model;
    const RenderRequest request = DiceRequest(12, 2);  // 6 passes
    std::vector<ShardFile> files;
    for (int64_t k = 0; k < 3; ++k) files.push_back(RenderShard(model, request, k, 3));
    EXPECT_EQ(MergeError(files), "");

    std::string e = MergeError({files[0], files[2]});
    EXPECT_NE(e.find("2 of 6 passes are missing (pass 2, 5; shard 2/3 not given)"),
              std::string::npos)
        << e;
    e = MergeError({files[0], files[1], files[2], files[1]});
    EXPECT_NE(e.find("pass 2 of 6 is in both 'part1' (2/3) and 'part3' (2/3)"), std::string::npos)
        << e;
    // Another split that overlaps: shard 1/2 holds passes 1, 3 and 5.
    e = MergeError({files[0], files[1], files[2], RenderShard(model, request, 0, 2)});
    EXPECT_NE(e.find("is in both"), std::string::npos) << e;
    // Another split that covers the passes exactly once is the same render.
    EXPECT_EQ(MergeError({RenderShard(model, request, 0, 2), RenderShard(model, request, 1, 2)}),
              "");
    // A shard of another render (another seed, or more paths): foreign.
    e = MergeError({files[0], files[1], RenderShard(model, DiceRequest(12, 2, 6), 2, 3)});
    EXPECT_NE(e.find("shard 'part2' is from another render than 'part0' (seed differ)"),
              std::string::npos)
        << e;
    // Another pass size: foreign.
    e = MergeError({files[0], files[1], RenderShard(model, DiceRequest(12, 3), 2, 3)});
    EXPECT_NE(e.find("(pass_spp differ)"), std::string::npos) << e;
    // More paths: the render of 14 (7 passes), whose last pass no shard holds.
    e = MergeError({files[0], files[1], RenderShard(model, DiceRequest(14, 2), 2, 3)});
    EXPECT_NE(e.find("1 of 7 passes are missing (pass 7 not given)"), std::string::npos) << e;
    // A shard with a pass short: unfinished (a checkpoint).
    ShardFile unfinished = files[1];
    unfinished.shard.pass_images.pop_back();
    e = MergeError({files[0], ParseShardFile(SerializeShardFile(unfinished), "x"), files[2]});
    EXPECT_NE(e.find("is unfinished"), std::string::npos) << e;
}

TEST(Shards, ALaterRoundExtendsTheRenderToTheOneProcessImageOfMorePaths) {
    const DiceModel model;
    // Round 1: 12 paths in passes of 3 (4 passes), two shards; then the
    // render of 21 paths (7 passes): round 2, passes 5 to 7, in two shards.
    std::vector<ShardFile> round1 = {RenderShard(model, DiceRequest(12, 3), 0, 2),
                                     RenderShard(model, DiceRequest(12, 3), 1, 2)};
    std::vector<ShardFile> round2 = {RenderShard(model, DiceRequest(21, 3), 0, 2, 4),
                                     RenderShard(model, DiceRequest(21, 3), 1, 2, 4)};
    EXPECT_EQ(round2[0].shard.pass_images.size(), 2u);  // passes 5 and 7
    EXPECT_EQ(round2[1].shard.pass_images.size(), 1u);  // pass 6
    for (const auto& [spp, files] :
         {std::make_pair(12, round1),
          std::make_pair(21, std::vector<ShardFile>{round2[1], round1[0], round2[0], round1[1]})}) {
        RenderRequest request = DiceRequest(spp, 3);
        Image one, one_variance;
        request.variance = &one_variance;
        model.Render(request, &one);
        Image merged, variance;
        MonteCarloReport report;
        MergeShards(files, std::vector<std::string>(files.size(), "part"), &merged, &variance,
                    &report);
        EXPECT_TRUE(SameBytes(merged, one)) << spp;
        EXPECT_TRUE(SameBytes(variance, one_variance)) << spp;
        EXPECT_EQ(report.samples, spp);
    }
    // Round 2 without a shard: missing; round 1 of 11 paths (a short last
    // pass of 2): not passes of the render of 21.
    std::string e = MergeError({round1[0], round1[1], round2[0]});
    EXPECT_NE(e.find("1 of 7 passes are missing (pass 6 not given)"), std::string::npos) << e;
    e = MergeError({RenderShard(model, DiceRequest(11, 3), 0, 2),
                    RenderShard(model, DiceRequest(11, 3), 1, 2), round2[0], round2[1]});
    EXPECT_NE(e.find("pass 4 in 'part1' holds 2 paths per pixel (its render: --spp 11) but 3"),
              std::string::npos)
        << e;
}

TEST(Shards, ShardFilesRefuseDamage) {
    const DiceModel model;
    const ShardFile file = RenderShard(model, DiceRequest(8, 2), 1, 2);
    const std::string bytes = SerializeShardFile(file);
    EXPECT_NO_THROW(ParseShardFile(bytes, "ok"));
    // Every byte matters (the checksum), a truncated file too.
    for (size_t at : {size_t{3}, size_t{20}, bytes.size() / 2, bytes.size() - 12}) {
        std::string damaged = bytes;
        damaged[at] = static_cast<char>(damaged[at] ^ 0x10);
        EXPECT_THROW(ParseShardFile(damaged, "damaged"), Error) << at;
    }
    EXPECT_THROW(ParseShardFile(bytes.substr(0, bytes.size() - 100), "truncated"), Error);
    // A pass list that is not the shard's (edited, checksum made to match).
    ShardFile edited = file;
    edited.shard.pass_images[0].index = 0;
    EXPECT_THROW(ParseShardFile(SerializeShardFile(edited), "edited"), Error);
}

TEST(Shards, AShardInterruptedAndResumedHoldsTheSamePasses) {
    const DiceModel model;
    RenderRequest request = DiceRequest(12, 3);  // 4 passes; shard 1/2: passes 1 and 3
    const ShardFile whole = RenderShard(model, request, 0, 2);
    const fs::path dir = TestDir("resume");
    request.checkpoint = (dir / "part").string();
    request.monte_carlo.checkpoint_seconds = 0.0;  // a checkpoint after every band (one row)
    // Interrupted inside the second pass (bands of one row: 4 per pass), then
    // between passes.
    for (int fail_at : {6, 4}) {
        fs::remove(dir / "part.bin");
        const DiceModel interrupted;
        interrupted.fail_at_band = fail_at;
        MonteCarloShard shard;
        shard.count = 2;
        {
            const ShardScope scope(&shard);
            Image ignored;
            EXPECT_THROW(interrupted.Render(request, &ignored), Error);
        }
        ASSERT_TRUE(fs::exists(dir / "part.bin"));
        const DiceModel resumed;
        request.resume = true;
        ShardFile file;
        file.shard.count = 2;
        {
            const ShardScope scope(&file.shard);
            Image ignored;
            resumed.Render(request, &ignored);
        }
        request.resume = false;
        EXPECT_EQ(resumed.bands, 8 - fail_at) << "resumed from the band it stopped at";
        ASSERT_EQ(file.shard.pass_images.size(), whole.shard.pass_images.size());
        for (size_t i = 0; i < whole.shard.pass_images.size(); ++i) {
            EXPECT_EQ(file.shard.pass_images[i].index, whole.shard.pass_images[i].index);
            EXPECT_TRUE(SameBytes(file.shard.pass_images[i].mean, whole.shard.pass_images[i].mean))
                << "pass " << i << " after an interruption at band " << fail_at;
        }
        EXPECT_EQ(file.shard.fingerprint, whole.shard.fingerprint);
    }
    // Another shard's checkpoint is refused.
    fs::remove(dir / "part.bin");
    Image ignored;
    {
        MonteCarloShard first;
        first.count = 2;
        const ShardScope scope(&first);
        const DiceModel stopped;
        stopped.fail_at_band = 2;
        EXPECT_THROW(stopped.Render(request, &ignored), Error);
    }
    request.resume = true;
    MonteCarloShard second;
    second.index = 1;
    second.count = 2;
    const ShardScope scope(&second);
    try {
        DiceModel().Render(request, &ignored);
        ADD_FAILURE() << "resumed another shard's checkpoint";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("different render or shard"), std::string::npos)
            << e.what();
    }
}

TEST(Shards, ShardsRefuseANoiseTargetAndTransmittance) {
    const DiceModel model;
    MonteCarloShard shard;
    shard.count = 2;
    const ShardScope scope(&shard);
    Image image;
    RenderRequest request = DiceRequest(8, 2);
    request.monte_carlo.noise_target = 0.05;
    EXPECT_THROW(model.Render(request, &image), Error);
    request = DiceRequest(8, 2);
    request.quantity = Quantity::kTransmittance;
    EXPECT_THROW(model.Render(request, &image), Error);
}

// The command line with the path tracer: one process against three shards
// merged (in another order), and the merge's refusals.
struct Result {
    int status = -1;
    std::string err;
};

Result RunCli(const std::string& args, const fs::path& dir) {
    const fs::path err = dir / "stderr.txt";
    const std::string cmd = std::string(ATMOS_CLI_PATH) + " " + args + " 2> " + err.string();
    const int raw = std::system(cmd.c_str());
    Result r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    std::ifstream f(err);
    r.err.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    return r;
}

std::string FileBytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

TEST(Shards, CliThreeShardsMergeToTheOneProcessImage) {
    const fs::path dir = TestDir("cli");
    const std::string common =
        "render -q --model reference --view ground-sunrise --size 16x8 --spp 10 --pass-spp 2 "
        "--seed 7 ";
    ASSERT_EQ(RunCli(common + "-o " + (dir / "one.exr").string(), dir).status, 0);
    for (int k = 1; k <= 3; ++k) {
        const std::string part = (dir / ("part" + std::to_string(k) + ".shard")).string();
        const Result r = RunCli(common + "--shard " + std::to_string(k) + "/3 -o " + part, dir);
        ASSERT_EQ(r.status, 0) << r.err;
    }
    const std::string p1 = (dir / "part1.shard").string(), p2 = (dir / "part2.shard").string(),
                      p3 = (dir / "part3.shard").string();
    // The fingerprint names what fixes the passes (the estimator's version too).
    const nlohmann::json fp =
        nlohmann::json::parse(ParseShardFile(FileBytes(p1), p1).shard.fingerprint);
    EXPECT_EQ(fp.at("model"), "reference");
    EXPECT_EQ(fp.at("view"), "ground-sunrise");
    EXPECT_EQ(fp.at("seed"), 7);
    EXPECT_EQ(fp.at("width"), 16);
    EXPECT_EQ(fp.at("pass_spp"), 2);
    EXPECT_TRUE(fp.at("model_key").contains("estimator_version")) << fp.dump();
    EXPECT_TRUE(fp.at("model_key").contains("atmosphere")) << fp.dump();
    Result r = RunCli(
        "merge -q " + p3 + " " + p1 + " " + p2 + " -o " + (dir / "merged.exr").string(), dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(FileBytes(dir / "one.exr").empty());
    EXPECT_EQ(FileBytes(dir / "merged.exr"), FileBytes(dir / "one.exr"));
    EXPECT_EQ(FileBytes(dir / "merged.variance.exr"), FileBytes(dir / "one.variance.exr"));
    // PNG through the view's exposure, as the render writes it.
    ASSERT_EQ(RunCli(common + "-o " + (dir / "one.png").string(), dir).status, 0);
    ASSERT_EQ(
        RunCli("merge -q " + p1 + " " + p2 + " " + p3 + " -o " + (dir / "merged.png").string(), dir)
            .status,
        0);
    EXPECT_EQ(FileBytes(dir / "merged.png"), FileBytes(dir / "one.png"));

    // A later round: 4 more paths per pixel (passes 6 and 7) in two shards;
    // merged with the first round, the render of 14 paths.
    const std::string more =
        "render -q --model reference --view ground-sunrise --size 16x8 --spp 14 --pass-spp 2 "
        "--seed 7 ";
    for (int k = 1; k <= 2; ++k) {
        const std::string part = (dir / ("round2-" + std::to_string(k) + ".shard")).string();
        r = RunCli(more + "--extend-from 10 --shard " + std::to_string(k) + "/2 -o " + part, dir);
        ASSERT_EQ(r.status, 0) << r.err;
    }
    ASSERT_EQ(RunCli(more + "-o " + (dir / "one14.exr").string(), dir).status, 0);
    r = RunCli("merge -q " + p1 + " " + (dir / "round2-2.shard").string() + " " + p2 + " " + p3 +
                   " " + (dir / "round2-1.shard").string() + " -o " +
                   (dir / "merged14.exr").string(),
               dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(FileBytes(dir / "merged14.exr"), FileBytes(dir / "one14.exr"));
    EXPECT_EQ(FileBytes(dir / "merged14.variance.exr"), FileBytes(dir / "one14.variance.exr"));
    r = RunCli(more + "--extend-from 9 --shard 1/2 -o " + (dir / "x.shard").string(), dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--extend-from must be a multiple of --pass-spp 2"), std::string::npos)
        << r.err;

    // Refusals: one line, exit 2, nothing written.
    auto refused = [&](const std::string& parts, const std::string& needle) {
        const fs::path out = dir / "refused.exr";
        const Result bad = RunCli("merge " + parts + " -o " + out.string(), dir);
        EXPECT_EQ(bad.status, 2) << parts;
        EXPECT_EQ(bad.err.rfind("atmos: error: ", 0), 0u) << bad.err;
        EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
        EXPECT_NE(bad.err.find(needle), std::string::npos) << bad.err;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_FALSE(fs::exists(dir / "refused.variance.exr"));
    };
    refused(p1 + " " + p3, "shard 2/3 not given");
    refused(p1 + " " + p2 + " " + p3 + " " + p2, "is in both");
    const std::string foreign = (dir / "foreign.shard").string();
    ASSERT_EQ(RunCli("render -q --model reference --view ground-sunrise --size 16x8 --spp 10 "
                     "--pass-spp 2 --seed 8 --shard 2/3 -o " +
                         foreign,
                     dir)
                  .status,
              0);
    refused(p1 + " " + foreign + " " + p3, "from another render");
    refused(p1 + " " + (dir / "one.exr").string(), "not a usable atmos shard");
    // --shard's own checks.
    r = RunCli(common + "--shard 4/3 -o " + (dir / "x.shard").string(), dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--shard must be K/N"), std::string::npos) << r.err;
    r = RunCli(common + "--shard 1/3 -o " + (dir / "x.exr").string(), dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("-o must end in .shard"), std::string::npos) << r.err;
    r = RunCli("render -q --model naive --size 16x8 --shard 1/3 -o " + (dir / "x.shard").string(),
               dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("is not one"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.shard"));
}

}  // namespace
}  // namespace atmos
