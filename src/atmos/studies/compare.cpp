// atmos studies: the compare study's defaults and policy (compare.h).
#include "studies/compare.h"

#include <cstdio>
#include <filesystem>
#include <string>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "harness/loc.h"
#include "render/progressive.h"
#include "studies/compare_views.h"

namespace atmos {

CompareConfig ResolveCompareConfig(const CompareRequest& q) {
    CompareConfig config;
    config.width = q.width;
    config.height = q.height;
    config.quantity = ParseQuantity(q.quantity);
    config.models = q.models;
    for (const std::string& m : q.models) ParseModelSpec(m);  // fail early
    config.atmosphere_name = q.atmosphere;
    config.atmosphere = LoadAtmosphere(q.atmosphere, q.sets);
    // Views: names of the 12, and the entries of views files in order.
    for (const std::string& v : q.views) {
        if (!IsCompareViewsFile(v)) {
            GetView(v, AtmosphereParameters{});  // fail early
            config.views.push_back(v);
            continue;
        }
        if (ParseQuantity(q.quantity) != Quantity::kRadiance) {
            Fail("--views ", v, ": custom views compare radiance (not --quantity ", q.quantity,
                 ")");
        }
        for (const CompareViewEntry& e : ReadCompareViews(v, q.width, q.height)) {
            config.custom_views.push_back(MakeCompareView(e, config.atmosphere));
            config.views.push_back(e.name);
        }
    }
    if (!q.views_json.empty()) {
        for (const CompareViewEntry& e :
             ParseCompareViews(q.views_json, "views", q.width, q.height)) {
            config.custom_views.push_back(MakeCompareView(e, config.atmosphere));
            config.views.push_back(e.name);
        }
    }
    for (size_t i = 0; i < config.views.size(); ++i) {
        for (size_t j = 0; j < i; ++j) {
            if (config.views[i] == config.views[j]) {
                Fail("--views: view '", config.views[i], "' is given twice");
            }
        }
    }
    if (!q.wavelengths.empty()) {
        // Spectral: every model and the reference at the wavelengths, as linear sRGB
        // (harness/spectral_run.h); the render cache is not used.
        if (q.colour != "srgb") Fail("compare --wavelengths compares --colour srgb");
        config.wavelengths = q.wavelengths;
        config.spectral_atmosphere = LoadSpectralAtmosphere(q.atmosphere, q.sets);
        config.white = ParseWhitePoint(q.white);
        for (const std::string& m : q.models)
            RequireSpectralModel(GetModelInfo(ParseModelSpec(m).name));
    }
    if (!q.reference_wavelengths.empty()) {
        // What RGB costs: the reference spectral (as linear sRGB), the models RGB.
        if (!q.wavelengths.empty()) {
            Fail("--reference-wavelengths compares the RGB models: drop --wavelengths");
        }
        if (config.quantity != Quantity::kRadiance) {
            Fail("--reference-wavelengths compares radiance");
        }
        if (q.colour != "srgb") Fail("compare --reference-wavelengths compares --colour srgb");
        config.reference_wavelengths = q.reference_wavelengths;
        config.spectral_atmosphere = LoadSpectralAtmosphere(q.atmosphere, q.sets);
        config.white = ParseWhitePoint(q.white);
    }
    config.output_dir = !q.output_dir.empty()                         ? q.output_dir
                        : config.quantity == Quantity::kTransmittance ? "out/transmittance"
                                                                      : "out";
    // CUDA images may differ from CPU ones in the last bits: their own cache.
    // The cache lives under the output directory unless cache_dir names one.
    const std::string cache = q.cache_dir            ? *q.cache_dir
                              : q.output_dir.empty() ? std::string("out/cache")
                                                     : q.output_dir + "/cache";
    config.cache_dir = q.no_cache ? "" : q.cuda ? cache + "/cuda" : cache;
    config.write_npy = q.write_npy;
    config.show_progress = q.show_progress;
    CheckFlipPpd(q.ppd);
    config.flip.ppd = q.ppd;
    config.flip.tone_mapper = ParseFlipToneMapper(q.tone_mapper);
    config.flip.exposure_setup = ParseFlipExposureSetup(q.exposure);
    config.command_line = q.command_line;
    config.batching = q.batching;
    config.machine = q.cuda ? "CUDA GPU" : "CPU";
    if (q.luminance) {
        if (config.quantity != Quantity::kRadiance) Fail("--luminance applies to radiance");
        if (!q.reference_wavelengths.empty()) {
            Fail(
                "--luminance: not with --reference-wavelengths (the reference's and the "
                "models' images are in different units there)");
        }
        config.luminance = true;
        if (HasPhysicalSolarSpectrum(LoadSpectralAtmosphere(q.atmosphere, q.sets))) {
            config.luminance_scale = kMaxLuminousEfficacy * CieYIntegral();
            config.luminance_note =
                std::string("cd m^-2: Y of the images (") +
                (q.wavelengths.empty() ? "Rec. 709 Y of RGB radiance at 680, 550, 440 nm"
                                       : "CIE 1931 Y of the spectral images") +
                ", W m^-2 sr^-1 nm^-1 with the atmosphere's tabulated solar spectrum in W m^-2 "
                "nm^-1) x 683 lm/W x 106.86 nm, per unit of the view's sun multiplier";
        } else {
            config.luminance_scale = SolarIlluminanceLux();
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.6g", config.luminance_scale);
            config.luminance_note =
                std::string(
                    "cd m^-2: Rec. 709 Y of the RGB images (radiance per unit solar "
                    "irradiance) x the Sun's illuminance at 1 AU, ") +
                buf +
                " lx (ASTM G173 extraterrestrial spectrum), per unit of the view's sun "
                "multiplier";
        }
    }

    // The reference: CompareConfig's default (the path tracer) unless one is named.
    if (q.reference) {
        const ModelSpec reference = ParseModelSpec(*q.reference);
        config.reference_model = reference.name;
        config.reference_options = reference.options;
        config.reference_note = "chosen with --reference " + *q.reference;
    } else {
        config.reference_note = "the path tracer";
    }
    const bool stochastic = GetModelInfo(config.reference_model).capabilities.stochastic;
    if (stochastic) {
        const double noise_flag = q.reference_noise.value_or(kCompareReferenceNoise);
        if (!(noise_flag >= 0.0 && noise_flag < 1.0)) {
            Fail("--reference-noise must be in [0, 1) (0: a fixed --reference-spp), got ",
                 noise_flag);
        }
        // The default is a noise target capped at kCompareReferenceCap paths;
        // reference_spp alone is a fixed count (noise off), with reference_noise the cap.
        const double noise = q.reference_noise ? *q.reference_noise
                             : q.reference_spp ? 0.0
                                               : kCompareReferenceNoise;
        const int64_t spp = noise > 0.0 && !q.reference_spp
                                ? kCompareReferenceCap
                                : q.reference_spp.value_or(kCompareReferenceSpp);
        config.reference_monte_carlo = MakeMonteCarloSettings(
            spp, q.reference_seed.value_or(0), 0, "--reference-spp", "--reference-seed");
        config.reference_monte_carlo.noise_target = noise;
    } else if (q.reference_spp || q.reference_seed || q.reference_noise) {
        Fail(
            "--reference-spp, --reference-seed and --reference-noise need a Monte Carlo "
            "reference model (",
            config.reference_model, " is not one)");
    }
    CreateModel(config.reference_model, config.reference_options);  // validate the options
    // Shipped references (harness/shipped_references.h): the directory named,
    // else data/references/WxH of the source tree when it exists and the
    // reference renders to a noise target (a fixed reference_spp asks for that
    // estimate: shipped ones only when named); no_shipped: never.
    const bool shipped_applies = stochastic && config.quantity == Quantity::kRadiance &&
                                 config.wavelengths.empty() && q.reference_wavelengths.empty();
    if (q.shipped_references) {
        if (q.no_shipped) {
            Fail("--shipped-references and --no-shipped-references exclude each other");
        }
        std::error_code ec;
        if (!std::filesystem::is_directory(*q.shipped_references, ec)) {
            Fail("--shipped-references: '", *q.shipped_references, "' is not a directory");
        }
        if (!shipped_applies) {
            Fail(
                "--shipped-references: shipped references stand for a Monte Carlo reference's "
                "RGB radiance (not with --quantity transmittance, --wavelengths or "
                "--reference-wavelengths)");
        }
        config.shipped_references = *q.shipped_references;
    } else if (!q.no_shipped && shipped_applies &&
               config.reference_monte_carlo.noise_target > 0.0) {
        const std::filesystem::path dir =
            std::filesystem::path(DefaultSourceDir()) / "data" / "references" /
            (std::to_string(config.width) + "x" + std::to_string(config.height));
        std::error_code ec;
        if (std::filesystem::is_directory(dir, ec)) config.shipped_references = dir.string();
    }
    if (!config.reference_wavelengths.empty()) {
        config.reference_note += "; rendered spectrally at " +
                                 std::to_string(config.reference_wavelengths.size()) +
                                 " wavelengths (--reference-wavelengths), the models in RGB; "
                                 "rgb_cost.csv compares each model with the RGB reference too";
    }
    return config;
}

bool HasPhysicalSolarSpectrum(const SpectralAtmosphere& atmosphere) {
    if (!atmosphere.spectral) return false;  // an RGB file: per unit solar irradiance
    for (const SpectralTerm& t : atmosphere.solar_irradiance.terms) {
        if (t.kind == SpectralTerm::Kind::kTable) return true;
    }
    return false;
}

double SolarIlluminanceLux() {
    std::vector<double> nm, e;
    SpectralDataTable("astm-g173-etr-10nm", 0, &nm, &e);
    const Vec3d xyz = SpectrumToXyz(nm, WavelengthWeights(nm), e.data());
    return kMaxLuminousEfficacy * xyz.y;
}

}  // namespace atmos
