#include "models/naive.h"

#include "atmos/error.h"
#include "render/wide.h"

namespace atmos {

ModelInfo NaiveModel::StaticInfo() {
    ModelInfo info;
    info.name = "naive";
    info.title = "Naive single scattering (Nishita 93)";
    info.citation =
        "Nishita et al. 1993; Terrell 2016 (glsl-atmosphere); Leenman's 2025 thesis sections 3.2, "
        "5.1, 11.2.6";
    info.summary = "single scattering by nested numerical integration, Rayleigh + Mie + ozone";
    info.capabilities.multiple_scattering = false;
    info.capabilities.wide_channels = true;
    info.options = OptionRows().Specs();
    info.thesis_name = "Naive";
    info.thesis_lines = 118;
    return info;
}

const OptionTable<NaiveOptions>& NaiveModel::OptionRows() {
    static const auto table =
        OptionTable<NaiveOptions>()
            .Integer("steps", &NaiveOptions::steps, 1, 1e5, "", "view-ray integration samples")
            .Integer("light-steps", &NaiveOptions::light_steps, 1, 1e5, "",
                     "light-ray integration samples");
    return table;
}

NaiveModel::NaiveModel(const NaiveOptions& options) {
    evaluator_.atm = EarthAtmosphere();
    evaluator_.steps = options.steps;
    evaluator_.light_steps = options.light_steps;
}

void NaiveModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                             const BatchPrepare&) {
    // No tables: each batch's Prepare() is its clipped atmosphere, made here.
    std::vector<AtmosphereParameters> clipped;
    for (const AtmosphereParameters& a : batches) {
        WarnOutsideValidityDomain(Info(), a);
        clipped.push_back(a);
        clipped.back().top_radius = EffectiveTopRadius(a);
    }
    wide_batches_ = clipped;
    // The shell ends at each batch's EffectiveTopRadius (Prepare): where they
    // differ (an atmosphere much thicker than its scale heights, whose column
    // depends on the wavelength) the rays differ too and there is no geometry
    // to share: RenderWide and SampleWide then run the batches one by one.
    wide_shared_ = true;
    for (const AtmosphereParameters& a : clipped) {
        wide_shared_ = wide_shared_ && a.top_radius == clipped[0].top_radius;
    }
    wide_.narrow = evaluator_;
    wide_.narrow.atm = clipped[0];
    if (wide_shared_) {
        wide_.w = MakeWideCoefficients(clipped);
    } else {
        wide_.w = WideCoefficients();
        wide_.w.channels = static_cast<int>(clipped.size()) * 3;
    }
}

void NaiveModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    if (wide_batches_.empty()) Fail("model naive: PrepareWide() must run before RenderWide()");
    if (wide_shared_) {
        RenderWideImage(wide_, MakeWidePixelSetup(request, wide_.narrow.atm, wide_.w), values);
        return;
    }
    const size_t n = wide_batches_.size() * 3;
    const size_t pixels = static_cast<size_t>(request.width) * request.height;
    values->assign(pixels * n, 0.0f);
    for (size_t b = 0; b < wide_batches_.size(); ++b) {
        NaiveEvaluator e = evaluator_;
        e.atm = wide_batches_[b];
        Image image(request.width, request.height);
        RenderImage(e, MakePixelSetup(request, e.atm), image.View(), false);
        for (size_t p = 0; p < pixels; ++p) {
            for (size_t c = 0; c < 3; ++c) (*values)[p * n + 3 * b + c] = image.data()[p * 3 + c];
        }
    }
}

std::vector<float> NaiveModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    if (wide_batches_.empty()) Fail("model naive: PrepareWide() must run before SampleWide()");
    if (wide_shared_) return SampleAllWide(wide_, wide_.narrow.atm.bottom_radius, queries);
    const size_t n = wide_batches_.size() * 3;
    std::vector<float> values(queries.size() * n, 0.0f);
    for (size_t b = 0; b < wide_batches_.size(); ++b) {
        NaiveEvaluator e = evaluator_;
        e.atm = wide_batches_[b];
        const std::vector<SampleAnswer> answers = SampleAll(e, e.atm.bottom_radius, queries);
        for (size_t q = 0; q < queries.size(); ++q) {
            for (size_t c = 0; c < 3; ++c) {
                values[q * n + 3 * b + c] = answers[q].radiance[static_cast<int>(c)];
            }
        }
    }
    return values;
}

}  // namespace atmos
