// atmos: the measured clear sky of Kider et al. 2014 (captures of 2013-05-27,
// data/kider-2013 in ../shared; README there) and the errors of a model against it.
//
// Errors (docs/harness.md "Measured sky"): over a set of (direction, bin) values,
// absolute RMSE = sqrt(mean((model - measured)^2)) in W m^-2 sr^-1 nm^-1, and
// relative RMSE = absolute RMSE / mean(measured) (the RMSE as a fraction of the
// mean measured radiance of the set).
#pragma once

#include <string>
#include <vector>

#include "atmos/model.h"

namespace atmos {

constexpr int kKiderBins = 40;  // 360 + 11.75 i nm

struct KiderSample {
    std::string capture;  // "09:30"
    int sample = 0;
    double elevation_deg = 0.0;
    double view_zenith_deg = 0.0;
    double sun_zenith_deg = 0.0;
    double view_sun_azimuth_deg = 0.0;  // with the sun azimuth estimated from the sky
    double view_sun_azimuth_theory_deg = 0.0;
    double gamma_deg = 0.0;
    bool suspect = false;
    double spectrum[kKiderBins] = {};
};

// The Kider wavelengths: 360 + 11.75 i nm, i = 0..39.
std::vector<double> KiderWavelengths();

// Reads kider_ref.csv (throws atmos::Error naming the file and line).
std::vector<KiderSample> ReadKiderCsv(const std::string& path);

// The query of a sample (altitude 0, the estimated sun azimuth unless `theory`).
SampleQuery KiderQuery(const KiderSample& sample, bool theory_azimuth);

// Where a sample lies: "near-sun" (gamma < 10 deg), "aureole" (10 <= gamma < 25
// deg), "zenith" (the zenith sample), "horizon" (the lowest ring, elevation 12.1
// deg), else "sky". The near-sun samples are few (19 of 1200) but bright: they
// carry about half the squared error of the models (docs/harness.md).
const char* KiderRegion(const KiderSample& sample);

// Accumulates squared errors and measured values.
struct ErrorSum {
    double squared = 0.0;
    double measured = 0.0;
    long count = 0;
    void Add(double model, double measured_value) {
        squared += (model - measured_value) * (model - measured_value);
        measured += measured_value;
        ++count;
    }
    double AbsoluteRmse() const;  // W m^-2 sr^-1 nm^-1
    double RelativeRmse() const;  // fraction
};

}  // namespace atmos
