// atmos CLI: `atmos flip REF TEST`: the FLIP difference of any two images.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "atmos/error.h"
#include "atmos/image.h"
#include "cli_common.h"
#include "io/output_path.h"
#include "metrics/flip.h"

namespace atmos::cli {

namespace {

struct FlipCliOptions {
    std::string reference, test, output, mode = "auto", tone_mapper = "aces", exposure = "atmos";
    double ppd = 0.0;
    double start = 0.0, stop = 0.0;
    int exposures = 0;
    CLI::Option* start_flag = nullptr;
    CLI::Option* stop_flag = nullptr;
};

int CmdFlip(const FlipCliOptions& o) {
    CheckFlipPpd(o.ppd);
    FlipOptions options;
    options.ppd = o.ppd;
    options.tone_mapper = ParseFlipToneMapper(o.tone_mapper);
    options.exposure_setup = ParseFlipExposureSetup(o.exposure);
    options.has_start_exposure = o.start_flag->count() > 0;
    options.start_exposure = o.start;
    options.has_stop_exposure = o.stop_flag->count() > 0;
    options.stop_exposure = o.stop;
    options.num_exposures = o.exposures;
    if (!o.output.empty()) {
        ImageFormatFromPath(o.output);  // fail early on a bad extension
        CheckOutputFile(o.output);      // and on an unwritable path (io/output_path.h)
    }
    bool hdr = false;
    if (o.mode == "auto") {
        hdr = ImageFormatFromPath(o.reference) != ImageFormat::kPng;
    } else if (o.mode == "hdr" || o.mode == "ldr") {
        hdr = o.mode == "hdr";
    } else {
        Fail("--mode must be auto, ldr or hdr");
    }
    const Image ref = ReadImage(o.reference);
    const Image test = ReadImage(o.test);
    const FlipResult r = hdr ? HdrFlip(ref, test, options) : LdrFlip(ref, test, options);
    const double ppd = options.ppd > 0.0 ? options.ppd : FlipDefaultPpd();
    if (hdr) {
        std::printf(
            "HDR-FLIP, tone mapper %s, exposure setup %s, ppd %.4f, exposures %.4f to %.4f (%d)\n",
            FlipToneMapperName(options.tone_mapper), FlipExposureSetupName(options.exposure_setup),
            ppd, r.exposures.start, r.exposures.stop, r.exposures.count);
    } else {
        std::printf("LDR-FLIP, ppd %.4f\n", ppd);
    }
    if (!o.output.empty()) {
        if (ImageFormatFromPath(o.output) == ImageFormat::kPng) {
            WriteColorMappedPng(r.map, r.width, r.height, o.output);
        } else {
            Image map(r.width, r.height);
            for (size_t i = 0; i < r.map.size(); ++i)
                map.data()[3 * i] = map.data()[3 * i + 1] = map.data()[3 * i + 2] = r.map[i];
            WriteImage(map, o.output);
        }
    }
    std::printf("mean FLIP: %.6f\n", r.mean);
    return 0;
}

}  // namespace

Command AddFlipCommand(CLI::App* root) {
    auto o = std::make_shared<FlipCliOptions>();
    CLI::App* cmd = root->add_subcommand(
        "flip", "FLIP difference of two images (HDR-FLIP unless the reference is a PNG)");
    cmd->add_option("reference", o->reference, "reference image (.exr .npy .pfm .png)")->required();
    cmd->add_option("test", o->test, "test image")->required();
    cmd->add_option("-o,--output", o->output,
                    "error map: .png (magma colour map), or .exr .npy .pfm (values)");
    cmd->add_option("--ppd", o->ppd, "pixels per degree (default 67.0206: 0.7 m, 0.7 m, 3840 px)");
    cmd->add_option("--tonemapper", o->tone_mapper, "HDR tone mapper: aces, hable, reinhard")
        ->capture_default_str();
    cmd->add_option("--exposure", o->exposure,
                    "HDR black pixels: atmos (exposure median over the non-black pixels) or thesis "
                    "(Leenman 2025 section 11.5: 1e-9 added to every pixel, median over all)")
        ->capture_default_str();
    cmd->add_option("--mode", o->mode, "auto (PNG reference: LDR), ldr or hdr")
        ->capture_default_str();
    o->start_flag = cmd->add_option("--start-exposure", o->start, "HDR start exposure (log2)");
    o->stop_flag = cmd->add_option("--stop-exposure", o->stop, "HDR stop exposure (log2)");
    cmd->add_option("--num-exposures", o->exposures, "HDR number of exposures")
        ->check(CLI::Range(0, 1000));
    return {cmd, [o] { return CmdFlip(*o); }};
}

}  // namespace atmos::cli
