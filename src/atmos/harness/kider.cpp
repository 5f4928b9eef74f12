// atmos: reading the Kider 2013 measurements and error sums.
#include "harness/kider.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "atmos/error.h"
#include "atmos/math.h"
#include "atmos/number.h"

namespace atmos {

std::vector<double> KiderWavelengths() {
    std::vector<double> nm;
    for (int i = 0; i < kKiderBins; ++i) nm.push_back(360.0 + 11.75 * i);
    return nm;
}

std::vector<KiderSample> ReadKiderCsv(const std::string& path) {
    std::ifstream in(path);
    if (!in) Fail("cannot read '", path, "' (the Kider 2013 data: give --data DIR)");
    std::string line;
    std::map<std::string, size_t> column;
    std::vector<KiderSample> samples;
    int line_number = 0;
    while (std::getline(in, line)) {
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> fields;
        std::stringstream ss(line);
        std::string field;
        while (std::getline(ss, field, ',')) fields.push_back(field);
        if (column.empty()) {
            for (size_t i = 0; i < fields.size(); ++i) column[fields[i]] = i;
            for (const char* required :
                 {"capture", "sample", "elevation_deg", "view_zenith_deg", "sun_zenith_deg",
                  "view_sun_azimuth_deg", "sun_azimuth_theory_deg", "sun_azimuth_est_deg",
                  "gamma_deg", "suspect", "S0", "S39"}) {
                if (column.count(required) == 0) {
                    Fail("'", path, "': the header has no column '", required, "'");
                }
            }
            continue;
        }
        if (fields.size() != column.size()) {
            Fail("'", path, "' line ", line_number, ": ", fields.size(), " fields, expected ",
                 column.size());
        }
        auto number = [&](const std::string& name) {
            double v = 0.0;
            const std::string& text = fields[column[name]];
            if (ParseNumber(text, &v) != NumberError::kNone) {
                Fail("'", path, "' line ", line_number, ": ", name, " '", text,
                     "' is not a number");
            }
            return v;
        };
        KiderSample s;
        s.capture = fields[column["capture"]];
        s.sample = static_cast<int>(number("sample"));
        s.elevation_deg = number("elevation_deg");
        s.view_zenith_deg = number("view_zenith_deg");
        s.sun_zenith_deg = number("sun_zenith_deg");
        s.view_sun_azimuth_deg = number("view_sun_azimuth_deg");
        s.view_sun_azimuth_theory_deg = s.view_sun_azimuth_deg + number("sun_azimuth_est_deg") -
                                        number("sun_azimuth_theory_deg");
        s.gamma_deg = number("gamma_deg");
        s.suspect = number("suspect") != 0.0;
        for (int i = 0; i < kKiderBins; ++i) s.spectrum[i] = number("S" + std::to_string(i));
        samples.push_back(s);
    }
    if (samples.empty()) Fail("'", path, "': no samples");
    return samples;
}

SampleQuery KiderQuery(const KiderSample& sample, bool theory_azimuth) {
    SampleQuery q;
    q.altitude_m = 0.0;
    q.mu = std::cos(sample.view_zenith_deg * kPi / 180.0);
    q.mu_s = std::cos(sample.sun_zenith_deg * kPi / 180.0);
    q.azimuth_deg =
        theory_azimuth ? sample.view_sun_azimuth_theory_deg : sample.view_sun_azimuth_deg;
    return q;
}

const char* KiderRegion(const KiderSample& sample) {
    if (sample.gamma_deg < 10.0) return "near-sun";
    if (sample.gamma_deg < 25.0) return "aureole";
    if (sample.view_zenith_deg < 1.0) return "zenith";
    if (sample.elevation_deg < 15.0) return "horizon";
    return "sky";
}

double ErrorSum::AbsoluteRmse() const {
    return count > 0 ? std::sqrt(squared / static_cast<double>(count)) : 0.0;
}

double ErrorSum::RelativeRmse() const {
    return count > 0 && measured > 0.0 ? AbsoluteRmse() / (measured / static_cast<double>(count))
                                       : 0.0;
}

}  // namespace atmos
