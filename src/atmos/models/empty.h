// atmos model `empty`: a constant white sky.
//
// Source: Leenman's 2025 thesis section 11.2.1 (the "empty shader"): it does no physics and
// measures the overhead of the render loop itself. Output: sky radiance 1 per
// unit solar irradiance for every ray (so a render shows the view's irradiance),
// transmittance 1. Valid: it is not a model of anything; it is a baseline.
#pragma once

#include "atmos/model.h"
#include "models/evaluator_model.h"

namespace atmos {

struct EmptyEvaluator {
    ATMOS_HD RayResult Evaluate(const Vec3d&, const Vec3d&, const Vec3d&, bool) const {
        RayResult r;
        r.sky = Rgb(1.0f);
        r.transmittance = Rgb(1.0f);
        return r;
    }
};

class EmptyModel : public SimpleEvaluatorModel<EmptyModel, EmptyEvaluator> {
  public:
    static const OptionTable<NoOptions>& OptionRows() { return NoOptionTable(); }
    explicit EmptyModel(const NoOptions&) {}
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override { SetAtmosphere(atmosphere); }
};

}  // namespace atmos
