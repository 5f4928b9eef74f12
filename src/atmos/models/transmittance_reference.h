// atmos model `transmittance-reference`: the view ray's transmittance by a
// Riemann sum of the extinction over the ray.
//
// Source: Leenman's 2025 thesis section 11.3.1 ("a naive Riemann integrator ... 128 steps");
// optical depth of Leenman's 2025 thesis Eq. 1 and 4 with Bruneton's 2017 implementation notes'
// layered profiles (Rayleigh scattering + Mie extinction + ozone absorption, the tent profile).
// Implements: tau = sum over `steps` (default 128) equal parts of the segment of
// the extinction at each part's midpoint times its length; T = exp(-tau).
// Output: transmittance only (radiance = false). Valid: anywhere; the midpoint
// rule's error falls as 1/steps^2. Deviation: midpoints (the seed does not say
// which Riemann sum).
#pragma once

#include "models/transmittance_common.h"
#include "physics/density.h"

namespace atmos {

struct ReferenceTransmittanceOptics {
    AtmosphereParameters atm;
    int steps = 128;

    ATMOS_HD Vec3d SegmentDepth(const Vec3d& origin, const Vec3d& dir, double t0, double t1) const {
        const double dt = (t1 - t0) / steps;
        Vec3d sum;
        for (int i = 0; i < steps; ++i) {
            const Vec3d p = origin + dir * (t0 + (i + 0.5) * dt);
            sum += Extinction(atm, GetDensities(atm, Length(p) - atm.bottom_radius));
        }
        return sum * dt;
    }
};

struct TransmittanceReferenceOptions {
    int steps = 128;  // Riemann-sum steps
};

class TransmittanceReferenceModel
    : public TransmittanceModel<TransmittanceReferenceModel, ReferenceTransmittanceOptics> {
  public:
    static const OptionTable<TransmittanceReferenceOptions>& OptionRows();
    explicit TransmittanceReferenceModel(const TransmittanceReferenceOptions& options);
    static ModelInfo StaticInfo();
    ReferenceTransmittanceOptics MakeOptics(const AtmosphereParameters& atmosphere) const;

  private:
    int steps_ = 128;
};

}  // namespace atmos
