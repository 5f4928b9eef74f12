// atmos CLI: `atmos merge PARTS... -o OUT`: the image of a Monte Carlo render
// from its shards (`render --shard K/N`, render/shards.h), byte for byte the
// image the render makes in one process.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/image.h"
#include "cli_common.h"
#include "io/output_path.h"
#include "render/shards.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

struct MergeOptions {
    std::vector<std::string> parts;
    std::string output;
    float exposure = 0.0f;  // 0: the view's, as the render would have used
    bool quiet = false;
};

int CmdMerge(const MergeOptions& o) {
    if (o.output.empty()) Fail("merge needs an output: -o FILE (.exr .png .npy .pfm)");
    if (o.parts.empty()) Fail("merge needs the shards: atmos merge PART.shard... -o FILE");
    if (!std::isfinite(o.exposure) || o.exposure < 0.0f) {
        Fail("--exposure must be a positive number");
    }
    // Every check before anything is written (io/output_path.h).
    ImageFormatFromPath(o.output);
    CheckOutputFile(o.output);
    const bool stream = IsStreamOutput(o.output);
    std::vector<ShardFile> files;
    for (const std::string& part : o.parts) files.push_back(ReadShardFile(part));
    Image image, variance;
    MonteCarloReport report;
    MergeShards(files, o.parts, &image, stream ? nullptr : &variance, &report);
    const nlohmann::json extra = nlohmann::json::parse(files[0].extra);
    const float exposure = o.exposure > 0.0f ? o.exposure : extra.value("exposure", 1.0f);
    const std::string stem = fs::path(o.output).replace_extension().string();
    if (!stream) CheckOutputFile(stem + ".variance.exr");
    WriteImage(image, o.output, exposure);
    if (!stream) WriteImage(variance, stem + ".variance.exr");
    if (!o.quiet) {
        std::fprintf(stderr,
                     "merged %zu shard(s): %lld passes, %lld paths per pixel, %dx%d -> %s\n",
                     files.size(), static_cast<long long>(files[0].shard.passes),
                     static_cast<long long>(report.samples), image.width(), image.height(),
                     o.output.c_str());
        if (report.noise >= 0.0) {
            std::fprintf(stderr,
                         "noise %.4f (HDR-FLIP between the even and the odd passes' means, as "
                         "render --noise measures it)\n",
                         report.noise);
        }
    }
    return 0;
}

}  // namespace

Command AddMergeCommand(CLI::App* root) {
    auto o = std::make_shared<MergeOptions>();
    Command c;
    CLI::App* merge = root->add_subcommand(
        "merge",
        "merge the shards of a Monte Carlo render (render --shard K/N) into its image and "
        "variance, byte for byte the one-process render's");
    merge->add_option("parts", o->parts, "the shards (FILE.shard), in any order")->required();
    merge
        ->add_option("-o,--output", o->output,
                     "the image (.exr .png .npy .pfm); its variance goes beside it as "
                     "STEM.variance.exr")
        ->required();
    merge->add_option("--exposure", o->exposure, "PNG exposure (default: the view's)");
    merge->add_flag("--quiet,-q", o->quiet, "no summary line");
    c.app = merge;
    c.run = [o] { return CmdMerge(*o); };
    return c;
}

}  // namespace atmos::cli
