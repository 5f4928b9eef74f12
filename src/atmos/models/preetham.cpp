#include "models/preetham.h"

#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"

namespace atmos {

namespace {

// data/spectra/cie-daylight-components.csv: CIE 15:2004 Table T.2, 10 nm, as
// three tabulated spectra (linear between the rows), and the Y of each.
struct DaylightComponents {
    double first_nm = 0.0, last_nm = 0.0;
    Spectrum s[3];
    double y[3] = {};
};

const DaylightComponents& Components() {
    static const DaylightComponents table = [] {
        DaylightComponents c;
        for (int k = 0; k < 3; ++k) {
            std::vector<double> nm, values;
            SpectralDataTable("cie-daylight-components", k, &nm, &values);
            c.first_nm = nm.front();
            c.last_nm = nm.back();
            c.s[k] = Spectrum::Table(std::move(nm), std::move(values));
        }
        for (int k = 0; k < 3; ++k) {
            c.y[k] = PipelineLuminance([&c, k](double l) { return c.s[k].At(l); });
        }
        return c;
    }();
    return table;
}

}  // namespace

double CieDaylightComponent(int k, double nm) {
    const DaylightComponents& c = Components();
    if (k < 0 || k > 2) Fail("CIE daylight component ", k, ": expected 0, 1 or 2");
    if (!(nm >= c.first_nm && nm <= c.last_nm)) {
        Fail("model preetham: ", WavelengthLabel(nm),
             " nm is outside the CIE daylight components (", WavelengthLabel(c.first_nm), "-",
             WavelengthLabel(c.last_nm), " nm) of its spectral form");
    }
    return c.s[k].At(nm);
}

double PipelineLuminance(const std::function<double(double)>& f) {
    std::vector<double> nm, ybar;  // the CIE table's wavelengths (ybar: SpectrumToXyz's own)
    SpectralDataTable("cie1931-2deg", 1, &nm, &ybar);
    std::vector<double> values(nm.size());
    for (size_t i = 0; i < nm.size(); ++i) values[i] = f(nm[i]);
    return SpectrumToXyz(nm, WavelengthWeights(nm), values.data()).y / CieYIntegral();
}

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
        "Preetham, Shirley & Smits 1999; Perez et al. 1993; Leenman's 2025 thesis sections 5.3 "
        "(Eq. 32-34), "
        "11.2.5; spectral form: CIE 15:2004 daylight components (Judd et al. 1964)";
    info.summary =
        "fitted Perez sky (xyY from turbidity) for a ground viewer; luminance / 128 klx as "
        "radiance per unit irradiance";
    info.capabilities = FittedSkyCapabilities();
    info.domain = FittedToEarthDomain();
    info.options = OptionRows().Specs();
    info.thesis_name = "Preetham, Shirley and Smits";
    info.thesis_lines = 58;
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
    evaluator_.spectral = spectral_;
    if (!spectral_) return;
    for (int k = 0; k < 3; ++k) evaluator_.basis_y[k] = Components().y[k];
    for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) evaluator_.basis[c][k] = CieDaylightComponent(k, nm_[c]);
        const double e = atmosphere.solar_irradiance[c];
        evaluator_.channel_scale[c] = e > 0.0 ? solar_y_ / e : 0.0;
    }
}

void PreethamModel::SetSpectralBatch(const SpectralAtmosphere& atmosphere, const double nm[3]) {
    for (int c = 0; c < 3; ++c) {
        CieDaylightComponent(0, nm[c]);  // fails outside the table
        nm_[c] = nm[c];
    }
    solar_y_ = PipelineLuminance([&](double l) { return atmosphere.solar_irradiance.At(l); });
    if (!(solar_y_ > 0.0)) {
        Fail("model preetham: the solar spectrum of atmosphere '", atmosphere.name,
             "' has no luminance (its Y over 360-830 nm is ", solar_y_, ")");
    }
    spectral_ = true;
}

}  // namespace atmos
