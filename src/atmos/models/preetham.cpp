#include "models/preetham.h"

namespace atmos {

double PreethamZenithLuminance(double T, double theta_s) {
    PreethamEvaluator e;
    e.turbidity = T;
    return e.ZenithLuminance(theta_s);
}
double PreethamZenithX(double T, double theta_s) {
    PreethamEvaluator e;
    e.turbidity = T;
    return e.ZenithChromaticity(theta_s, true);
}
double PreethamZenithY(double T, double theta_s) {
    PreethamEvaluator e;
    e.turbidity = T;
    return e.ZenithChromaticity(theta_s, false);
}

ModelInfo PreethamModel::StaticInfo() {
    ModelInfo info;
    info.name = "preetham";
    info.title = "Preetham, Shirley & Smits 1999 analytic daylight";
    info.citation =
        "Preetham, Shirley & Smits 1999; Perez et al. 1993; seed 003 sections 5.3 (Eq. 32-34), "
        "11.2.5";
    info.summary =
        "fitted Perez sky (xyY from turbidity) for a ground viewer; luminance / 128 klx as "
        "radiance per unit irradiance";
    info.capabilities.transmittance = false;
    info.capabilities.space_views = false;
    info.capabilities.sun_below_horizon = false;
    info.capabilities.multiple_scattering = true;  // fitted to a full simulation
    info.options = OptionRows().Specs();
    return info;
}

const OptionTable<PreethamOptions>& PreethamModel::OptionRows() {
    static const auto table = OptionTable<PreethamOptions>().Real(
        "turbidity", &PreethamOptions::turbidity, 1.7, 10.0, "", "atmospheric turbidity T");
    return table;
}

PreethamModel::PreethamModel(const PreethamOptions& options) {
    const double T = options.turbidity;
    evaluator_.turbidity = T;
    evaluator_.kY = PreethamLuminanceCoefficients(T);
    evaluator_.kx = PreethamXCoefficients(T);
    evaluator_.ky = PreethamYCoefficients(T);
    Prepare(EarthAtmosphere());
}

void PreethamModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.bottom = atmosphere.bottom_radius;
    evaluator_.top = atmosphere.top_radius;
}

}  // namespace atmos
