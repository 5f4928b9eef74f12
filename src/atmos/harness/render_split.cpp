// atmos: the split of a render and the merge of its pieces (see render_split.h).
#include "harness/render_split.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <utility>

#include "atmos/error.h"
#include "io/output_path.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

bool EndsWith(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

const char* Splitter(const RenderSplit& split) { return split.sharded() ? "--shard" : "mpirun"; }

}  // namespace

void ParseShardSpec(const std::string& text, int64_t* index, int64_t* count) {
    const size_t slash = text.find('/');
    long long k = 0, n = 0;
    size_t used_k = 0, used_n = 0;
    // Digits only on either side: no sign, space or other text (std::stoll
    // would skip leading white space and take a '+').
    bool ok = slash != std::string::npos && slash > 0 && slash + 1 < text.size() &&
              text.find_first_not_of("0123456789/") == std::string::npos;
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

void CheckRenderSplit(RenderSplit* split, const RenderSplitTarget& target) {
    const bool sharded = split->sharded();
    if (sharded) {
        ParseShardSpec(split->shard, &split->shard_index, &split->shard_count);
        if (split->world_size > 1) {
            Fail("--shard cannot be combined with mpirun (the ranks are the shards)");
        }
        if (target.all_views) Fail("--shard renders one view: give --view NAME, not --view all");
        if (!EndsWith(target.output, ".shard") && !IsStreamOutput(target.output)) {
            Fail("--shard writes the shard's passes, not an image: -o must end in .shard (got '",
                 target.output, "'); `atmos merge` makes the image");
        }
    } else if (EndsWith(target.output, ".shard")) {
        Fail("-o ", target.output, ": a .shard output needs --shard K/N");
    }
    if (split->extend_from != 0) {
        // A later round: the passes after the first EXTEND paths per pixel.
        if (!sharded) Fail("--extend-from needs --shard K/N (a later round of shards)");
        if (target.pass_spp <= 0) {
            Fail("--extend-from needs --pass-spp P (the same in every round: it fixes the passes)");
        }
        if (split->extend_from < 0 || split->extend_from % target.pass_spp != 0 ||
            split->extend_from >= target.spp) {
            Fail("--extend-from must be a multiple of --pass-spp ", target.pass_spp,
                 " below --spp ", target.spp, " (the earlier round's --spp), got ",
                 split->extend_from);
        }
    }
    if (!split->split()) return;
    if (target.spectral) {
        Fail(Splitter(*split), " splits RGB renders only; --wavelengths cannot be split (yet)");
    }
    if (target.quantity != Quantity::kRadiance) {
        Fail(Splitter(*split), " splits the passes of a Monte Carlo radiance render; --quantity ",
             target.quantity_name, " is not one");
    }
    if (target.noise_target) {
        Fail(Splitter(*split),
             " splits a render of a fixed --spp; --noise (a target reached by rendering until "
             "it holds) cannot be split (`atmos merge` prints the noise reached; more paths: "
             "a later round of shards, --extend-from, docs/scale-out.md)");
    }
}

void CheckRenderSplitModel(const RenderSplit& split, const ModelInfo& info) {
    if (split.split() && !info.capabilities.stochastic) {
        Fail(Splitter(split), " splits the passes of a Monte Carlo model; model ", info.name,
             " is not one (`atmos list` marks them)");
    }
}

MonteCarloShard RenderSplitShard(const RenderSplit& split, int64_t pass_spp) {
    MonteCarloShard shard;
    shard.index = split.sharded() ? split.shard_index : split.world_rank;
    shard.count = split.sharded() ? split.shard_count : split.world_size;
    if (split.extend_from > 0) shard.first_pass = split.extend_from / pass_spp;
    return shard;
}

void WriteRenderShard(const std::string& path, MonteCarloShard* shard, const std::string& view,
                      float exposure, double seconds) {
    // The shard's passes and the render's fingerprint (render/shards.h).
    ShardFile file;
    file.shard = std::move(*shard);
    nlohmann::json extra;
    extra["view"] = view;
    extra["exposure"] = exposure;
    extra["seconds"] = seconds;
    file.extra = extra.dump();
    const std::string bytes = SerializeShardFile(file);
    *shard = std::move(file.shard);
    WriteFileAtomically(path, bytes);
}

void MergeRankShards(std::vector<MonteCarloShard> shards, Image* image, Image* variance,
                     MonteCarloReport* report) {
    // Every rank's passes, merged in pass order.
    std::vector<ShardFile> files(shards.size());
    std::vector<std::string> names;
    for (size_t r = 0; r < shards.size(); ++r) {
        files[r].shard = std::move(shards[r]);
        names.push_back("rank " + std::to_string(r));
    }
    MergeShards(files, names, image, variance, report);
}

void MergeShardFilesToImage(const std::vector<std::string>& parts, const std::string& output,
                            float exposure, bool quiet) {
    if (output.empty()) Fail("merge needs an output: -o FILE (.exr .png .npy .pfm)");
    if (parts.empty()) Fail("merge needs the shards: atmos merge PART.shard... -o FILE");
    if (!std::isfinite(exposure) || exposure < 0.0f) {
        Fail("--exposure must be a positive number");
    }
    // Every check before anything is written (io/output_path.h).
    ImageFormatFromPath(output);
    CheckOutputFile(output);
    const bool stream = IsStreamOutput(output);
    std::vector<ShardFile> files;
    for (const std::string& part : parts) files.push_back(ReadShardFile(part));
    Image image, variance;
    MonteCarloReport report;
    MergeShards(files, parts, &image, stream ? nullptr : &variance, &report);
    const nlohmann::json extra = nlohmann::json::parse(files[0].extra);
    const float used = exposure > 0.0f ? exposure : extra.value("exposure", 1.0f);
    const std::string stem = fs::path(output).replace_extension().string();
    if (!stream) CheckOutputFile(stem + ".variance.exr");
    WriteImage(image, output, used);
    if (!stream) WriteImage(variance, stem + ".variance.exr");
    if (quiet) return;
    std::fprintf(stderr, "merged %zu shard(s): %lld passes, %lld paths per pixel, %dx%d -> %s\n",
                 files.size(), static_cast<long long>(files[0].shard.passes),
                 static_cast<long long>(report.samples), image.width(), image.height(),
                 output.c_str());
    if (report.noise >= 0.0) {
        std::fprintf(stderr,
                     "noise %.4f (HDR-FLIP between the even and the odd passes' means, as "
                     "render --noise measures it)\n",
                     report.noise);
    }
}

}  // namespace atmos
