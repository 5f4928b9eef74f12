// atmos: the shared shape of the transmittance models (`transmittance-*`).
//
// A transmittance model computes only the view ray's transmittance (Leenman's 2025 thesis
// section 11.3): its capabilities say radiance = false, its Evaluate() fills
// RayResult::transmittance = exp(-tau) over the part of the ray inside the
// atmosphere (to the ground or to space; a camera in space starts where the
// ray enters) and leaves the sky and ground at zero. They work with
// `atmos render --quantity transmittance` and `atmos sample`.
//
// Each model supplies an "optics" struct with
//   ATMOS_HD Vec3d SegmentDepth(origin, dir, t0, t1) const
// returning the optical depth of the segment [t0, t1] of origin + t dir.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "physics/geometry.h"

namespace atmos {

template <typename Optics>
struct TransmittanceEvaluator {
    Optics optics;
    double bottom = 6360e3;
    double top = 6460e3;

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d&, bool) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, bottom, top, &out, &seg)) return out;
        const Vec3d tau = optics.SegmentDepth(camera, dir, seg.t_start, seg.t_end);
        out.transmittance = Rgb(Exp(-Max(tau, Vec3d(0.0))));
        return out;
    }
};

// The capabilities every transmittance model shares.
inline ModelCapabilities TransmittanceCapabilities() {
    ModelCapabilities c;
    c.radiance = false;
    c.transmittance = true;
    return c;
}

// Host side: Derived implements `static ModelInfo StaticInfo()` and
// `Optics MakeOptics(const AtmosphereParameters&) const`.
template <typename Derived, typename Optics>
class TransmittanceModel : public SimpleEvaluatorModel<Derived, TransmittanceEvaluator<Optics>> {
  public:
    void Prepare(const AtmosphereParameters& atmosphere) override {
        this->SetAtmosphere(atmosphere);
        this->evaluator_.bottom = atmosphere.bottom_radius;
        this->evaluator_.top = atmosphere.top_radius;
        this->evaluator_.optics = static_cast<const Derived&>(*this).MakeOptics(atmosphere);
    }
};

// A transmittance model without options whose optics are Optics{Make(atmosphere)}
// (transmittance-erfc, -flat, -polynomial). Derived implements `static ModelInfo
// StaticInfo()` and a constructor from NoOptions.
template <typename Derived, typename Optics, typename Data,
          Data (*Make)(const AtmosphereParameters&)>
class OptionlessTransmittanceModel : public TransmittanceModel<Derived, Optics> {
  public:
    static const OptionTable<NoOptions>& OptionRows() { return NoOptionTable(); }
    Optics MakeOptics(const AtmosphereParameters& atmosphere) const {
        return Optics{Make(atmosphere)};
    }
};

}  // namespace atmos
