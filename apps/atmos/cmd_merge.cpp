// atmos CLI: `atmos merge PARTS... -o OUT`: the image of a Monte Carlo render
// from its shards (`render --shard K/N`, render/shards.h), byte for byte the
// image the render makes in one process (harness/render_split.h).
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "harness/render_split.h"

namespace atmos::cli {

namespace {

struct MergeOptions {
    std::vector<std::string> parts;
    std::string output;
    float exposure = 0.0f;  // 0: the view's, as the render would have used
    bool quiet = false;
};

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
    c.run = [o] {
        MergeShardFilesToImage(o->parts, o->output, o->exposure, o->quiet);
        return 0;
    };
    return c;
}

}  // namespace atmos::cli
