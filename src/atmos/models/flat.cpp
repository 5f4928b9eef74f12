#include "models/flat.h"

#include "atmos/error.h"
#include "render/wide.h"

namespace atmos {

ModelInfo FlatModel::StaticInfo() {
    ModelInfo info;
    info.name = "flat";
    info.title = "Flat / homogeneous-sphere single scattering (Leenman's 2025 thesis s. 10)";
    info.citation =
        "Jodie 2019; Rapp-Arraras & Domingo-Santos 2011; Leenman's 2025 thesis sections 10.1-10.5 "
        "(Eq. 45-55, 59), 11.2.9";
    info.summary =
        "closed-form single scattering over one segment, homogeneous-sphere optical depth, "
        "ozone shell";
    info.capabilities.wide_channels = true;
    info.thesis_name = "Flat";
    info.thesis_lines = 58;
    return info;
}

FlatModel::FlatModel(const NoOptions&) { Prepare(EarthAtmosphere()); }

void FlatModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.optics.m = MakeAnalyticMedia(atmosphere);
}

FlatWideMedia MakeFlatWideMedia(const std::vector<AtmosphereParameters>& batches) {
    MakeWideCoefficients(batches);  // the batches differ only in their coefficients
    FlatWideMedia w;
    w.optics.m = MakeAnalyticMedia(batches[0]);
    w.channels = static_cast<int>(batches.size()) * 3;
    for (size_t b = 0; b < batches.size(); ++b) {
        const AnalyticMedia m = MakeAnalyticMedia(batches[b]);
        // The shell's geometry is the absorption profile's; a batch without
        // absorption has none (and a 0 coefficient).
        if (w.optics.m.ozone.Empty() && !m.ozone.Empty()) w.optics.m.ozone = m.ozone;
        for (int c = 0; c < 3; ++c) {
            const size_t k = 3 * b + static_cast<size_t>(c);
            w.rayleigh_scattering[k] = m.rayleigh_scattering[c];
            w.mie_scattering[k] = m.mie_scattering[c];
            w.mie_extinction[k] = m.mie_extinction[c];
            w.ozone_absorption[k] = m.ozone_absorption[c];
            w.ground_albedo[k] = m.ground_albedo[c];
        }
    }
    return w;
}

void FlatModel::PrepareWide(const std::vector<AtmosphereParameters>& batches, const BatchPrepare&) {
    // No tables: each batch's Prepare() is its AnalyticMedia, made here.
    wide_ = PreparedWide<FlatWideEvaluator>();
    wide_.coefficients = MakeWideCoefficients(batches);
    for (const AtmosphereParameters& a : batches) WarnOutsideValidityDomain(Info(), a);
    wide_.evaluator.w = MakeFlatWideMedia(batches);
    wide_.atmosphere = batches[0];
    wide_.prepared = true;
}

void FlatModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    RenderPreparedWide("flat", wide_, request, values);
}

std::vector<float> FlatModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    return SamplePreparedWide("flat", wide_, queries);
}

}  // namespace atmos
