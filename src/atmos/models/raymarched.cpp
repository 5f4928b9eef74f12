#include "models/raymarched.h"

#include "atmos/error.h"
#include "render/wide.h"

namespace atmos {

ModelInfo RaymarchedModel::StaticInfo() {
    ModelInfo info;
    info.name = "raymarched";
    info.title = "Raymarched segments with the flat optical depth (Leenman's 2025 thesis s. 10.4)";
    info.citation = "Hillaire 2015; Leenman's 2025 thesis sections 10.2-10.5 (Eq. 50-59), 11.2.10";
    info.summary =
        "single scattering summed over a few closed-form segments (Eq. 55), flat optical "
        "depth, ozone shell";
    info.capabilities.wide_channels = true;
    info.options = OptionRows().Specs();
    info.thesis_name = "Raymarched";
    info.thesis_lines = 74;
    return info;
}

const OptionTable<RaymarchedOptions>& RaymarchedModel::OptionRows() {
    static const auto table = OptionTable<RaymarchedOptions>().Integer(
        "steps", &RaymarchedOptions::steps, 1, 1e5, "", "view-ray segments");
    return table;
}

RaymarchedModel::RaymarchedModel(const RaymarchedOptions& options) {
    evaluator_.steps = options.steps;
    Prepare(EarthAtmosphere());
}

void RaymarchedModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.optics.m = MakeAnalyticMedia(atmosphere);
}

void RaymarchedModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                                  const BatchPrepare&) {
    // No tables: each batch's Prepare() is its AnalyticMedia, made here.
    wide_ = PreparedWide<RaymarchedWideEvaluator>();
    wide_.coefficients = MakeWideCoefficients(batches);
    for (const AtmosphereParameters& a : batches) WarnOutsideValidityDomain(Info(), a);
    wide_.evaluator.steps = evaluator_.steps;
    wide_.evaluator.w = MakeFlatWideMedia(batches);
    wide_.atmosphere = batches[0];
    wide_.prepared = true;
}

void RaymarchedModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    RenderPreparedWide("raymarched", wide_, request, values);
}

std::vector<float> RaymarchedModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    return SamplePreparedWide("raymarched", wide_, queries);
}

}  // namespace atmos
