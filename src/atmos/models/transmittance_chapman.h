// atmos model `transmittance-chapman`: the view ray's transmittance from
// Schuler 2012's Chapman-function approximation.
//
// Source: Leenman's 2025 thesis section 5.1, Eq. 22-25. Implements: each exponential
// medium's optical length to infinity from ChapmanLengthToInfinity (Eq. 24-25,
// mu >= 0 branch), segments by SegmentFromToInfinity (which reproduces Eq. 24's
// complement branch for rays that pass the tangent point, and uses two upward
// rays for segments to the ground); T = exp(-tau). No ozone (as `schuler`).
// `--chapman-unit seed` (default) is Eq. 25 as printed (unit: the scale
// height); `half-height` is Schuler's own unit, the 50% height H ln 2.
// Output: transmittance only. Valid: as the approximation (error: docs/models/transmittance.md).
#pragma once

#include "models/transmittance_common.h"
#include "physics/analytic_media.h"

namespace atmos {

struct ChapmanUpLength {
    double H, bottom, unit;
    ATMOS_HD double operator()(double r, double mu) const {
        return ChapmanLengthToInfinity(r, mu, H, bottom, unit);
    }
};

struct ChapmanTransmittanceOptics {
    AnalyticMedia m;
    double unit = kChapmanSeedUnit;  // `--chapman-unit`: see ChapmanLengthToInfinity

    ATMOS_HD Vec3d SegmentDepth(const Vec3d& origin, const Vec3d& dir, double t0, double t1) const {
        return RayleighMieSegmentDepth(
            m.rayleigh_scattering, ChapmanUpLength{m.rayleigh_H, m.bottom, unit}, m.mie_extinction,
            ChapmanUpLength{m.mie_H, m.bottom, unit}, origin, dir, t0, t1);
    }
};

struct TransmittanceChapmanOptions {
    double chapman_unit = kChapmanSeedUnit;
};

class TransmittanceChapmanModel
    : public TransmittanceModel<TransmittanceChapmanModel, ChapmanTransmittanceOptics> {
  public:
    static const OptionTable<TransmittanceChapmanOptions>& OptionRows();
    explicit TransmittanceChapmanModel(const TransmittanceChapmanOptions& options);
    static ModelInfo StaticInfo();
    ChapmanTransmittanceOptics MakeOptics(const AtmosphereParameters& atmosphere) const {
        return ChapmanTransmittanceOptics{MakeAnalyticMedia(atmosphere), unit_};
    }

  private:
    double unit_ = kChapmanSeedUnit;
};

// The `chapman-unit` option shared by `schuler` and `transmittance-chapman`:
// its choices (name -> unit) and help.
std::vector<std::pair<std::string, double>> ChapmanUnitChoices();
extern const char* const kChapmanUnitHelp;

}  // namespace atmos
