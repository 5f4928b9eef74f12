// atmos studies: the writers of a spectral sample run (spectral_sample.h).
#include "studies/spectral_sample.h"

#include <algorithm>
#include <charconv>

#include "atmos/spectral.h"

namespace atmos {

std::string SpectralSampleCsv(const std::vector<double>& nm,
                              const std::vector<SampleQuery>& queries,
                              const std::vector<double>& values) {
    const std::vector<double> weights = WavelengthWeights(nm);
    const std::vector<Vec3d> cmf = Cie1931At(nm);
    const size_t n = nm.size();
    std::string text;
    char cell[64];
    // Each number as its shortest text that reads back to the same value
    // (std::to_chars without a precision): a query's input as a double (as
    // the RGB `sample` echoes it), a radiance and X, Y, Z as a float (the
    // models answer in float; before 0.3.0 printf's "%.9g": with the
    // colour-matching functions interpolated per query, 100,269 instructions
    // a query at 40 wavelengths with the `empty` model, now 30,126).
    const auto put = [&](bool comma, bool query, double v) {
        if (comma) text += ',';
        const std::to_chars_result r =
            query ? std::to_chars(cell, cell + sizeof cell, v, std::chars_format::general)
                  : std::to_chars(cell, cell + sizeof cell, static_cast<float>(v),
                                  std::chars_format::general);
        text.append(cell, static_cast<size_t>(r.ptr - cell));
    };
    text += "altitude_m,mu,mu_s,azimuth_deg";
    for (double l : nm) text += ",L_" + WavelengthLabel(l);
    text += ",X,Y,Z\n";
    for (size_t q = 0; q < queries.size(); ++q) {
        put(false, true, queries[q].altitude_m);
        put(true, true, queries[q].mu);
        put(true, true, queries[q].mu_s);
        put(true, true, queries[q].azimuth_deg);
        for (size_t i = 0; i < n; ++i) put(true, false, values[q * n + i]);
        const Vec3d xyz = SpectrumToXyz(cmf, weights, values.data() + q * n);
        put(true, false, kMaxLuminousEfficacy * xyz.x);
        put(true, false, kMaxLuminousEfficacy * xyz.y);
        put(true, false, kMaxLuminousEfficacy * xyz.z);
        text += "\n";
    }
    return text;
}

std::vector<float> SpectralSampleArray(const std::vector<double>& nm, size_t queries,
                                       const std::vector<double>& values) {
    const std::vector<double> weights = WavelengthWeights(nm);
    const std::vector<Vec3d> cmf = Cie1931At(nm);
    const size_t n = nm.size();
    std::vector<float> array(queries * (n + 3));
    for (size_t q = 0; q < queries; ++q) {
        float* row = array.data() + q * (n + 3);
        for (size_t i = 0; i < n; ++i) row[i] = static_cast<float>(values[q * n + i]);
        const Vec3d xyz = SpectrumToXyz(cmf, weights, values.data() + q * n);
        for (int k = 0; k < 3; ++k) {
            row[n + static_cast<size_t>(k)] = static_cast<float>(kMaxLuminousEfficacy * xyz[k]);
        }
    }
    return array;
}

}  // namespace atmos
