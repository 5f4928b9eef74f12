#include "models/flat.h"

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
    info.thesis_name = "Flat";
    info.thesis_lines = 58;
    return info;
}

FlatModel::FlatModel(const NoOptions&) { Prepare(EarthAtmosphere()); }

void FlatModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.optics.m = MakeAnalyticMedia(atmosphere);
}

}  // namespace atmos
