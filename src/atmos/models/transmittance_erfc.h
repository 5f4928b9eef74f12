// atmos model `transmittance-erfc`: the view ray's transmittance from Bruneton
// & Neyret 2008's erfc approximation of the optical depth.
//
// Source: Leenman's 2025 thesis section 5.1, Eq. 26-30 and Listing 3 (from Bruneton &
// Neyret's 2008 implementation). Implements: each exponential medium's optical
// length along the segment (physics/analytic_optical_depth.h,
// ErfcSegmentLength: altitude along the ray h + t mu + t^2/(2r), Eq. 27-28,
// integrated with erfc, Eq. 29, approximated by Eq. 30); T = exp(-tau).
// No ozone (the approximation is for exponential media; this model leaves the
// ozone out rather than invent a form for it). Output: transmittance only.
// Valid: segments that stay where t^2/(2r) is a good approximation of the
// altitude gain (short compared to r); the whole atmosphere qualifies.
#pragma once

#include "models/transmittance_common.h"
#include "physics/analytic_media.h"
#include "physics/analytic_optical_depth.h"

namespace atmos {

struct ErfcTransmittanceOptics {
    AnalyticMedia m;

    ATMOS_HD Vec3d SegmentDepth(const Vec3d& origin, const Vec3d& dir, double t0, double t1) const {
        const auto [r, mu, d] = RaySegmentStartOf(origin, dir, t0, t1);
        return m.rayleigh_scattering * ErfcSegmentLength(r, mu, d, m.rayleigh_H, m.bottom) +
               m.mie_extinction * ErfcSegmentLength(r, mu, d, m.mie_H, m.bottom);
    }
};

class TransmittanceErfcModel
    : public OptionlessTransmittanceModel<TransmittanceErfcModel, ErfcTransmittanceOptics,
                                          AnalyticMedia, MakeAnalyticMedia> {
  public:
    explicit TransmittanceErfcModel(const NoOptions&) { Prepare(EarthAtmosphere()); }
    static ModelInfo StaticInfo();
};

}  // namespace atmos
