// atmos model `transmittance-flat`: the view ray's transmittance from the
// flat / homogeneous-sphere optical depth.
//
// Source: Leenman's 2025 thesis section 11.3.3 (Eq. 50, 53, 60) and section 10.5 (ozone
// shell, Eq. 59). Implements: tau of the segment from models/flat.h
// (FlatOptics::SegmentDepth: Eq. 51 per medium, Eq. 53's decomposition looking
// down, segments to the ground by Bruneton & Neyret's difference of two
// upward rays, which uses the ground point as the thesis says; exact chord
// through the ozone shell); T = exp(-tau) (Eq. 60).
// Output: transmittance only. Valid: best looking up; the horizontal optical
// length of Eq. 50 is sqrt(2 r H) where the exponential's is sqrt(pi r H / 2),
// 13% more, hence "slightly more absorption near the horizon" (Leenman's 2025 thesis s. 12.2).
#pragma once

#include "models/flat.h"
#include "models/transmittance_common.h"

namespace atmos {

class TransmittanceFlatModel
    : public OptionlessTransmittanceModel<TransmittanceFlatModel, FlatOptics, AnalyticMedia,
                                          MakeAnalyticMedia> {
  public:
    explicit TransmittanceFlatModel(const NoOptions&) { Prepare(EarthAtmosphere()); }
    static ModelInfo StaticInfo();
};

}  // namespace atmos
