#include "models/naive.h"

namespace atmos {

ModelInfo NaiveModel::StaticInfo() {
    ModelInfo info;
    info.name = "naive";
    info.title = "Naive single scattering (Nishita 93)";
    info.citation =
        "Nishita et al. 1993; Terrell 2016 (glsl-atmosphere); seed 003 sections 3.2, 5.1, 11.2.6";
    info.summary = "single scattering by nested numerical integration, Rayleigh + Mie + ozone";
    info.capabilities.multiple_scattering = false;
    info.options = {
        {"steps",
         ModelOptionSpec::Type::kInteger,
         "16",
         "view-ray integration samples",
         1,
         1e5,
         {}},
        {"light-steps",
         ModelOptionSpec::Type::kInteger,
         "8",
         "light-ray integration samples",
         1,
         1e5,
         {}},
    };
    return info;
}

NaiveModel::NaiveModel(const ModelOptions& options) {
    evaluator_.atm = EarthAtmosphere();
    evaluator_.steps = options.GetInt("steps");
    evaluator_.light_steps = options.GetInt("light-steps");
}

}  // namespace atmos
