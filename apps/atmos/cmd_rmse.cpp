// atmos CLI: `atmos rmse REF TEST`: RMSE per channel and overall, and PSNR, of any two images.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "atmos/error.h"
#include "atmos/image.h"
#include "cli_common.h"
#include "metrics/rmse.h"

namespace atmos::cli {

namespace {

int CmdRmse(const std::string& reference, const std::string& test, double peak) {
    if (!(peak > 0.0) || !std::isfinite(peak)) Fail("--peak must be a positive number");
    const RmseResult r = ComputeRmse(ReadImage(reference), ReadImage(test));
    std::printf("RMSE per channel: R %.8g G %.8g B %.8g\n", r.channel[0], r.channel[1],
                r.channel[2]);
    const double psnr = Psnr(r.mse, peak);
    if (std::isinf(psnr)) {
        std::printf("PSNR: inf dB (identical, peak %g)\n", peak);
    } else {
        std::printf("PSNR: %.4f dB (peak %g)\n", psnr, peak);
    }
    std::printf("RMSE: %.8g\n", r.overall);
    return 0;
}

}  // namespace

Command AddRmseCommand(CLI::App* root) {
    auto ref = std::make_shared<std::string>();
    auto test = std::make_shared<std::string>();
    auto peak = std::make_shared<double>(1.0);
    CLI::App* cmd = root->add_subcommand("rmse", "RMSE (per channel and overall) and PSNR");
    cmd->add_option("reference", *ref, "reference image (.exr .npy .pfm .png)")->required();
    cmd->add_option("test", *test, "test image")->required();
    cmd->add_option("--peak", *peak, "signal peak for PSNR")->capture_default_str();
    return {cmd, [ref, test, peak] { return CmdRmse(*ref, *test, *peak); }};
}

}  // namespace atmos::cli
