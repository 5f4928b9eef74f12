// atmos model `hosek-wilkie`: the coefficient file of a fitted Hosek-Wilkie sky
// (`atmos fit --model hosek-wilkie` writes it, `hosek-wilkie:coefficients=FILE`
// reads it; docs/models/hosek-wilkie.md "Fitted to any atmosphere").
//
// Layout (JSON, one object):
//   "format": "atmos-hosek-wilkie-coefficients", "format_version": 1,
//   "units": a sentence (radiance per unit solar irradiance, 1/sr),
//   "parameters": ["A","B","C","D","E","F","G","I","H","L_M"] (the data order
//     of the published coefficients: the anisotropy H after I),
//   "channels": 3 arrays (the atmosphere's R, G, B channels) of 6 control
//     points (the quintic Bezier over x = (elevation / (pi/2))^(1/3)) of those
//     10 values: channels[c][point][parameter],
//   "fit": {"reference": model spec, "atmosphere": name or file as given,
//     "atmosphere_parameters": the atmosphere's JSON, and the fit's settings and
//     residuals (informative; only "reference" and "atmosphere" are required)}.
// L_M is in atmos's units (per unit solar irradiance): the model's output is
// F(theta, gamma) L_M with no further constant.
#pragma once

#include <string>

namespace atmos {

constexpr const char* kHosekWilkieCoefficientsFormat = "atmos-hosek-wilkie-coefficients";
constexpr int kHosekWilkieCoefficientsVersion = 1;

struct HosekWilkieCoefficients {
    // channel, control point, A B C D E F G I H L_M
    double ctrl[3][6][10] = {};
    std::string reference;   // the model spec fitted to
    std::string atmosphere;  // the atmosphere as given (preset name or file)
    // The rest of the "fit" object as JSON text (written as is; "{}" when none).
    std::string fit_json = "{}";
};

// The file's text (pretty-printed JSON; numbers in their shortest round-trip form, so
// reading it back gives the same doubles).
std::string HosekWilkieCoefficientsToJson(const HosekWilkieCoefficients& c);

// Parses `text`; one atmos::Error naming `source` and the bad field otherwise
// (not JSON, wrong format or version, a missing field, a wrong shape, a value
// not finite, a negative L_M).
HosekWilkieCoefficients HosekWilkieCoefficientsFromJson(const std::string& text,
                                                        const std::string& source);

// Reads and parses the file `path` (at most 1 MiB).
HosekWilkieCoefficients LoadHosekWilkieCoefficients(const std::string& path);

}  // namespace atmos
