// The progressive driver (render/progressive.h) for any model that declares
// itself Monte Carlo: a test-only stochastic model whose pixels are means of
// uniform random numbers, passes weighted by their counts, checkpoint and
// resume, the variance, and one clear error for models that are not Monte Carlo.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "base/fnv1a.h"
#include "base/progress.h"
#include "base/rng.h"
#include "metrics/flip.h"
#include "render/progressive.h"
#include "test_util.h"

namespace atmos {
namespace {

// Pixel (x, y), channel c of a pass: the mean of Rng(seed, pixel, sample)'s c-th
// uniform over the pass's samples. `stochastic` is its capability flag; the
// class is a Monte Carlo model either way (the driver must go by the flag).
class CoinModel : public Model {
  public:
    explicit CoinModel(bool stochastic) {
        info_.name = "coin";
        info_.capabilities.stochastic = stochastic;
    }
    const ModelInfo& Info() const override { return info_; }
    void Prepare(const AtmosphereParameters&) override {}
    void Render(const RenderRequest& request, Image* out) const override {
        RenderProgressive(*this, request, out);
    }
    std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const override {
        return SampleMonteCarlo(*this, queries, MonteCarloSettings());
    }
    void RenderPass(const RenderRequest& request, const MonteCarloPass& pass, Image* out,
                    Progress* progress) const override {
        if (bands_rendered == fail_at_band) throw Error("coin: an injected failure");
        ++bands_rendered;
        if (pass.row_begin == 0) ++passes_rendered;
        const int rows = pass.rows > 0 ? pass.rows : request.height - pass.row_begin;
        out->Resize(request.width, rows);
        for (int y = 0; y < rows; ++y) {
            const int row = pass.row_begin + y;
            for (int x = 0; x < request.width; ++x) {
                out->Set(x, y, Rgb(Mean(pass, static_cast<uint64_t>(row * request.width + x))));
            }
        }
        if (progress) progress->Add(static_cast<int64_t>(request.width) * rows);
    }
    std::vector<SampleAnswer> SamplePass(const std::vector<SampleQuery>& queries,
                                         const MonteCarloPass& pass) const override {
        std::vector<SampleAnswer> answers(queries.size());
        for (size_t i = 0; i < queries.size(); ++i) answers[i].radiance = Rgb(Mean(pass, i));
        return answers;
    }
    std::string PassKey() const override { return "{\"coin\": 1}"; }

    static Vec3d Mean(const MonteCarloPass& pass, uint64_t key) {
        Vec3d sum(0.0);
        for (int64_t s = pass.first_sample; s < pass.first_sample + pass.samples; ++s) {
            Rng rng(pass.seed, key, static_cast<uint64_t>(s));
            for (int c = 0; c < 3; ++c) sum[c] += rng.Uniform();
        }
        return sum / static_cast<double>(pass.samples);
    }

    mutable int passes_rendered = 0;  // passes begun at row 0
    mutable int bands_rendered = 0;
    mutable int fail_at_band = -1;  // >= 0: RenderPass throws for that band (0: the first)

  private:
    ModelInfo info_;
};

RenderRequest CoinRequest(int64_t spp, int64_t pass_spp) {
    return atmos_test::MonteCarloRequest(GetView("ground-noon", EarthAtmosphere()), 5, 3, spp,
                                         pass_spp, 11);
}

std::filesystem::path TestDir(const char* name) { return atmos_test::FreshTestTmpDir(name); }

// Renders `request` with a checkpoint in the fresh folder `dir_name` and
// returns the checkpoint file's path (request->checkpoint set).
std::string WriteCoinCheckpoint(const CoinModel& model, const char* dir_name,
                                RenderRequest* request, Image* image) {
    request->checkpoint = (TestDir(dir_name) / "coin").string();
    model.Render(*request, image);
    return request->checkpoint + ".bin";
}

// Resumes request's checkpoint to 12 samples per pixel into *resumed and
// returns how many passes that rendered.
int ResumeToTwelveSamples(const CoinModel& model, RenderRequest* request, Image* resumed) {
    request->monte_carlo.spp = 12;
    request->resume = true;
    const int before = model.passes_rendered;
    model.Render(*request, resumed);
    return model.passes_rendered - before;
}

// A checkpoint's bytes with the trailing FNV-1a checksum recomputed (after an edit).
std::string ResumCheckpoint(std::string bytes) {
    const uint64_t h = Fnv1a(bytes.data(), bytes.size() - 8);
    std::memcpy(&bytes[bytes.size() - 8], &h, 8);
    return bytes;
}

TEST(Progressive, PassesOfAnyMonteCarloModelWeightedByTheirCounts) {
    const CoinModel model(true);
    RenderRequest request = CoinRequest(10, 4);  // passes of 4, 4 and 2 samples
    Image image, variance;
    request.variance = &variance;
    model.Render(request, &image);
    EXPECT_EQ(model.passes_rendered, 3);
    ASSERT_EQ(variance.size(), image.size());
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 5; ++x) {
            const uint64_t key = static_cast<uint64_t>(y * 5 + x);
            MonteCarloPass all;
            all.seed = 11;
            all.samples = 10;
            const Vec3d mean = CoinModel::Mean(all, key);
            // Batch means: sum_p n_p (m_p - mean)^2 / (N (passes - 1)).
            Vec3d var(0.0);
            for (int64_t first : {0, 4, 8}) {
                MonteCarloPass p = all;
                p.first_sample = first;
                p.samples = first == 8 ? 2 : 4;
                const Vec3d d = CoinModel::Mean(p, key) - mean;
                var += d * d * static_cast<double>(p.samples) / (10.0 * 2.0);
            }
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(image.Get(x, y)[c], mean[c], 1e-6);
                EXPECT_NEAR(variance.Get(x, y)[c], var[c], 1e-6);
            }
        }
    }
    // The default pass size: spp / 8 in [1, 64].
    EXPECT_EQ(PassSpp(CoinRequest(64, 0).monte_carlo), 8);
    EXPECT_EQ(PassSpp(CoinRequest(5, 0).monte_carlo), 1);
    EXPECT_EQ(PassSpp(CoinRequest(4096, 0).monte_carlo), 64);
    EXPECT_EQ(PassSpp(CoinRequest(4096, 3).monte_carlo), 3);
}

TEST(Progressive, OnPassIsCalledAfterEveryPassAndCanStopTheRender) {
    const CoinModel model(true);
    RenderRequest request = CoinRequest(10, 4);  // 3 passes
    std::vector<std::pair<int64_t, int64_t>> calls;
    request.on_pass = [&](int64_t done, int64_t total) { calls.emplace_back(done, total); };
    Image image;
    model.Render(request, &image);
    const std::vector<std::pair<int64_t, int64_t>> expected = {{1, 3}, {2, 3}, {3, 3}};
    EXPECT_EQ(calls, expected);
    // A throwing callback stops after that pass; the error reaches the caller.
    request.on_pass = [](int64_t done, int64_t) {
        if (done == 2) throw Error("stop");
    };
    model.passes_rendered = 0;
    EXPECT_THROW(model.Render(request, &image), Error);
    EXPECT_EQ(model.passes_rendered, 2);
}

TEST(Progressive, ResumesACheckpointOfAnyMonteCarloModel) {
    const CoinModel model(true);
    Image full;
    model.Render(CoinRequest(12, 3), &full);
    const std::filesystem::path dir = TestDir("progressive_resume");
    RenderRequest request = CoinRequest(6, 3);
    request.checkpoint = (dir / "coin").string();
    Image partial;
    model.Render(request, &partial);
    Image resumed;
    EXPECT_EQ(ResumeToTwelveSamples(model, &request, &resumed), 2);  // passes 3 and 4 only
    ASSERT_EQ(resumed.size(), full.size());
    EXPECT_EQ(std::memcmp(resumed.data(), full.data(), full.size() * sizeof(float)), 0);
    // Another seed or pass size is another render: refused.
    request.monte_carlo.seed = 12;
    EXPECT_THROW(model.Render(request, &resumed), Error);
    request.monte_carlo.seed = 11;
    request.monte_carlo.pass_spp = 4;
    EXPECT_THROW(model.Render(request, &resumed), Error);
}

TEST(Progressive, ModelsThatAreNotMonteCarloFailClearly) {
    // The same class without the capability flag: the driver refuses it.
    const CoinModel flagless(false);
    Image image;
    EXPECT_ERROR_CONTAINS(flagless.Render(CoinRequest(4, 0), &image),
                          "coin is not a Monte Carlo model");
    EXPECT_EQ(flagless.passes_rendered, 0);
    EXPECT_THROW(SampleMonteCarlo(flagless, {SampleQuery()}, MonteCarloSettings()), Error);
    // A registered deterministic model.
    std::unique_ptr<Model> naive = CreateModel("naive");
    EXPECT_THROW(RenderProgressive(*naive, CoinRequest(4, 0), &image), Error);
    EXPECT_THROW(SampleMonteCarlo(*naive, {SampleQuery()}, MonteCarloSettings()), Error);
    EXPECT_THROW(naive->RenderPass(CoinRequest(4, 0), MonteCarloPass(), &image, nullptr), Error);
    // Monte Carlo models take no spp / seed / pass-spp options any more.
    EXPECT_THROW(CreateModel("reference", {{"spp", "4"}}), Error);
    EXPECT_THROW(CreateModel("reference", {{"seed", "4"}}), Error);
    EXPECT_THROW(CreateModel("reference", {{"pass-spp", "4"}}), Error);
}

TEST(Progressive, SettingsAreValidatedWithOneClearError) {
    EXPECT_EQ(MakeMonteCarloSettings(1, 4294967295ll, 0).seed, 4294967295ull);
    EXPECT_EQ(MakeMonteCarloSettings(7, 3, 2).spp, 7);
    for (const auto& [spp, seed, pass, needle] :
         {std::make_tuple(0, 0, 0, "--spp must be at least 1"),
          std::make_tuple(-3, 0, 0, "--spp must be at least 1"),
          std::make_tuple(1, -1, 0, "--seed must be in [0, 4294967295]"),
          std::make_tuple(1, 1, -1, "--pass-spp must be >= 0")}) {
        EXPECT_ERROR_CONTAINS(MakeMonteCarloSettings(spp, seed, pass), needle);
    }
    EXPECT_THROW(MakeMonteCarloSettings(1, 4294967296ll, 0), Error);
    // The driver itself refuses an empty render.
    const CoinModel model(true);
    Image image;
    EXPECT_THROW(model.Render(CoinRequest(0, 0), &image), Error);
    EXPECT_THROW(model.Render(CoinRequest(4, -1), &image), Error);
}

// Issue 18 item 1: --resume verifies what it reads. A truncated or damaged
// checkpoint, counts that disagree, or a sum that is not finite (each with a
// valid checksum where the damage is not the checksum's to find) is one clear
// error, never a wrong image.
TEST(Progressive, ADamagedCheckpointIsOneClearError) {
    const CoinModel model(true);
    RenderRequest request = CoinRequest(6, 3);
    Image image;
    const std::string path = WriteCoinCheckpoint(model, "progressive_damaged", &request, &image);
    const std::string good = atmos_test::Slurp(path);
    ASSERT_GT(good.size(), 16u + 2 * 5 * 3 * 3 * sizeof(float));
    auto write = [&](const std::string& bytes) {
        std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    };
    request.monte_carlo.spp = 12;
    request.resume = true;
    auto expect_damaged = [&](const std::string& bytes, const char* why) {
        write(bytes);
        try {
            model.Render(request, &image);
            ADD_FAILURE() << "resumed from a checkpoint with " << why;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("is damaged"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    };
    expect_damaged(good.substr(0, good.size() - 100), "checksum");
    expect_damaged(good.substr(0, 12), "truncated");
    std::string flipped = good;
    flipped[good.size() - 20] ^= 0x10;
    expect_damaged(flipped, "checksum");
    const size_t at = good.find("\"samples_done\":6");
    ASSERT_NE(at, std::string::npos);
    std::string counts = good;
    counts[at + 15] = '2';  // 2 samples in 2 passes of 3
    expect_damaged(ResumCheckpoint(counts), "counts disagree");
    std::string nan = good;
    const float q = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&nan[good.size() - 8 - 4], &q, 4);
    expect_damaged(ResumCheckpoint(nan), "not finite");
    std::string longer = good;
    longer.insert(good.size() - 8, 4, '\0');
    expect_damaged(ResumCheckpoint(longer), "wrong size");
    // The intact checkpoint resumes to the uninterrupted image.
    write(good);
    Image resumed, full;
    model.Render(request, &resumed);
    model.Render(CoinRequest(12, 3), &full);
    EXPECT_EQ(std::memcmp(resumed.data(), full.data(), full.size() * sizeof(float)), 0);
    // The temporary file is gone once committed.
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

// Issue 39 item 6: a hand-edited checkpoint with a recomputed checksum whose
// sums are out of range (negative, the even half above the whole, a sum of
// squares too small for its sum and count, non-zero sums where no sample was
// taken) or whose fingerprint is another render's is refused; a directory or
// a FIFO in its place is one clear error, never a block.
TEST(Progressive, ACheckpointsSumsAreRangeChecked) {
    const CoinModel model(true);
    RenderRequest request = CoinRequest(6, 3);
    Image image;
    const std::string path = WriteCoinCheckpoint(model, "progressive_ranges", &request, &image);
    const std::string good = atmos_test::Slurp(path);
    uint64_t header_size = 0;
    std::memcpy(&header_size, good.data() + 8, 8);
    const size_t sums = 16 + header_size, n = 5 * 3 * 3;
    auto with_float = [&](size_t index, float value) {
        std::string bytes = good;
        std::memcpy(&bytes[sums + 4 * index], &value, 4);
        return ResumCheckpoint(bytes);
    };
    request.monte_carlo.spp = 12;
    request.resume = true;
    auto expect_refused = [&](const std::string& bytes, const char* why) {
        std::filesystem::remove_all(path);
        std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
        EXPECT_ERROR_CONTAINS(model.Render(request, &image), why);
    };
    float sum0 = 0.0f, sq0 = 0.0f;
    std::memcpy(&sum0, &good[sums], 4);
    std::memcpy(&sq0, &good[sums + 4 * n], 4);
    ASSERT_GT(sum0, 0.0f);
    expect_refused(with_float(0, -sum0), "negative");
    expect_refused(with_float(n, -sq0), "negative");
    // sum^2 <= samples x sum_sq: a sum of squares of a tenth breaks it.
    expect_refused(with_float(n, sq0 * 0.1f), "disagree with the sample counts");
    // A sum 100 times larger, its square sum as it was.
    expect_refused(with_float(0, sum0 * 100.0f), "disagree with the sample counts");
    // The fingerprint: another seed is another render.
    std::string seed = good;
    const size_t at = seed.find("\"seed\":11");
    ASSERT_NE(at, std::string::npos);
    seed[at + 8] = '2';
    expect_refused(ResumCheckpoint(seed), "different render");
    EXPECT_NE(good.find("\"estimator_version\""), std::string::npos);
    // A directory, a FIFO: one clear error at once.
    std::filesystem::remove(path);
    std::filesystem::create_directories(path);
    EXPECT_ERROR_CONTAINS(model.Render(request, &image), "is a directory");
    std::filesystem::remove(path);
    ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
    EXPECT_ERROR_CONTAINS(model.Render(request, &image), "not a regular file");
    std::filesystem::remove(path);
    // The intact checkpoint still resumes.
    std::ofstream(path, std::ios::binary) << good;
    EXPECT_NO_THROW(model.Render(request, &image));
}

}  // namespace
}  // namespace atmos

namespace atmos {
namespace {

// The FLIP between a coin render's first pair of passes (seed 11, 3 samples
// each): the even pass (samples 0-2) against the odd one (3-5).
FlipResult EvenOddFlip(const Model& model, const RenderRequest& request) {
    Image even, odd;
    MonteCarloPass pass;
    pass.seed = 11;
    pass.samples = 3;
    model.RenderPass(request, pass, &even, nullptr);
    pass.first_sample = 3;
    model.RenderPass(request, pass, &odd, nullptr);
    return HdrFlip(even, odd);
}

// A noise target: pairs of passes (even and odd: the two halves), checked as
// they grow, stopping at the target or the spp cap; the image is the plain
// render of the same samples, and a checkpoint (with the halves) resumes it.
TEST(Progressive, RendersToANoiseTargetOrTheCap) {
    const CoinModel model(true);
    Image plain;
    model.Render(CoinRequest(12, 3), &plain);
    // Unreachable: the cap, above the target, the same image as the plain render.
    RenderRequest request = CoinRequest(12, 3);
    request.monte_carlo.noise_target = 1e-6;
    MonteCarloReport report;
    request.report = &report;
    Image capped;
    model.Render(request, &capped);
    EXPECT_EQ(report.samples, 12);
    EXPECT_GT(report.noise, 1e-6);
    ASSERT_EQ(capped.size(), plain.size());
    EXPECT_EQ(std::memcmp(capped.data(), plain.data(), plain.size() * sizeof(float)), 0);
    // Reached at once: one pair of passes.
    request.monte_carlo.noise_target = 0.99;
    Image quick;
    model.Render(request, &quick);
    EXPECT_EQ(report.samples, 6);
    EXPECT_LE(report.noise, 0.99);
    // The noise is the FLIP between the even pass (samples 0-2) and the odd one (3-5).
    EXPECT_NEAR(report.noise, EvenOddFlip(model, request).mean, 1e-6);
    // Resumed from a checkpoint of the first pair: the capped image again.
    const std::filesystem::path dir = TestDir("progressive_noise");
    request.monte_carlo.noise_target = 1e-6;
    request.monte_carlo.spp = 6;
    request.checkpoint = (dir / "coin").string();
    model.Render(request, &quick);
    Image resumed;
    EXPECT_EQ(ResumeToTwelveSamples(model, &request, &resumed), 2);
    EXPECT_EQ(report.samples, 12);
    EXPECT_EQ(std::memcmp(resumed.data(), plain.data(), plain.size() * sizeof(float)), 0);
    // A noise target out of range is one clear error.
    request.monte_carlo.noise_target = 1.5;
    EXPECT_THROW(model.Render(request, &resumed), Error);
}

}  // namespace
}  // namespace atmos

namespace atmos {
namespace {

// Issue 18 item 10: a checkpoint may fall inside a pass (bands of rows; with
// checkpoint_seconds 0 one row each and a checkpoint after every band). A
// render stopped by a failure at any band resumes from its last checkpoint to
// exactly the uninterrupted image and variance, rendering only the bands left:
// plain passes (a short last one included) and noise-targeted pairs (stopped
// inside an odd pass or after an even one).
TEST(Progressive, ACheckpointInsideAPassResumesToTheSameImage) {
    const std::filesystem::path dir = TestDir("progressive_bands");
    for (const bool noise : {false, true}) {
        RenderRequest request = CoinRequest(10, 4);  // 3 passes (4, 4, 2) of 7 rows
        request.height = 7;
        if (noise) {
            request.monte_carlo.spp = 8;
            request.monte_carlo.pass_spp = 2;  // 4 passes (2 pairs), the noise not reached
            request.monte_carlo.noise_target = 1e-6;
        }
        const int bands = noise ? 28 : 21;
        Image full, full_variance;
        request.variance = &full_variance;
        const CoinModel whole(true);
        whole.Render(request, &full);
        request.checkpoint = (dir / "coin").string();
        request.monte_carlo.checkpoint_seconds = 0.0;
        for (const int k : {1, 3, 7, 8, 12, 15, 20, 24}) {
            if (k >= bands) continue;
            std::filesystem::remove(request.checkpoint + ".bin");
            const CoinModel failing(true);
            failing.fail_at_band = k;
            request.resume = false;
            Image image, variance;
            request.variance = &variance;
            EXPECT_THROW(failing.Render(request, &image), Error) << k;
            const CoinModel model(true);
            request.resume = true;
            model.Render(request, &image);
            EXPECT_EQ(model.bands_rendered, bands - k) << noise << " " << k;
            ASSERT_EQ(image.size(), full.size());
            EXPECT_EQ(std::memcmp(image.data(), full.data(), full.size() * sizeof(float)), 0)
                << noise << " " << k;
            EXPECT_EQ(
                std::memcmp(variance.data(), full_variance.data(), full.size() * sizeof(float)), 0)
                << noise << " " << k;
        }
    }
    // A checkpoint interval that is not a number of seconds is one clear error.
    RenderRequest request = CoinRequest(4, 2);
    request.monte_carlo.checkpoint_seconds = -1.0;
    Image image;
    EXPECT_THROW(CoinModel(true).Render(request, &image), Error);
}

}  // namespace
}  // namespace atmos

namespace atmos {
namespace {

// A noise-targeted render returns the halves' per-pixel FLIP map with its
// noise (issue 33 item 2: the reference's noise per region): the map of the
// even pass against the odd one, whose float32 mean is the noise; a render
// resumed from a checkpoint that already reached its target measures it at
// resume time and returns the same map; a fixed-spp render returns none.
TEST(Progressive, ANoiseTargetReturnsTheHalvesFlipMap) {
    const CoinModel model(true);
    RenderRequest request = CoinRequest(12, 3);
    MonteCarloReport report;
    request.report = &report;
    Image image;
    model.Render(request, &image);
    EXPECT_LT(report.noise, 0.0);
    EXPECT_TRUE(report.noise_map.empty());
    request.monte_carlo.noise_target = 0.99;  // reached after one pair
    const std::filesystem::path dir = TestDir("progressive_noise_map");
    request.checkpoint = (dir / "coin").string();
    model.Render(request, &image);
    EXPECT_EQ(report.samples, 6);
    const FlipResult halves = EvenOddFlip(model, request);
    ASSERT_EQ(report.noise_map.size(), static_cast<size_t>(request.width * request.height));
    float sum = 0.0f;
    for (size_t i = 0; i < report.noise_map.size(); ++i) {
        EXPECT_NEAR(report.noise_map[i], halves.map[i], 1e-5) << i;
        sum += report.noise_map[i];
    }
    EXPECT_EQ(report.noise, static_cast<double>(sum) / static_cast<double>(halves.map.size()));
    // Resumed: the target reached at resume time, no pass rendered, the same map.
    const std::vector<float> first = report.noise_map;
    const double first_noise = report.noise;
    report = MonteCarloReport();
    request.resume = true;
    const int before = model.passes_rendered;
    Image resumed;
    model.Render(request, &resumed);
    EXPECT_EQ(model.passes_rendered, before);
    EXPECT_EQ(report.noise, first_noise);
    EXPECT_EQ(report.noise_map, first);
    EXPECT_EQ(std::memcmp(resumed.data(), image.data(), image.size() * sizeof(float)), 0);
}

}  // namespace
}  // namespace atmos
