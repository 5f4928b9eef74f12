// atmos model `hosek-wilkie`: the fitted coefficient file (hosek_wilkie_coefficients.h).
#include "models/hosek_wilkie_coefficients.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "atmos/error.h"
#include "io/bounded_read.h"

namespace atmos {

namespace {

constexpr const char* kParameterNames[10] = {"A", "B", "C", "D", "E", "F", "G", "I", "H", "L_M"};

}  // namespace

std::string HosekWilkieCoefficientsToJson(const HosekWilkieCoefficients& c) {
    nlohmann::ordered_json j;
    j["format"] = kHosekWilkieCoefficientsFormat;
    j["format_version"] = kHosekWilkieCoefficientsVersion;
    j["units"] =
        "L = F(theta, gamma) L_M, radiance per unit solar irradiance (1/sr) of the "
        "atmosphere's R, G, B channels";
    j["parameters"] = kParameterNames;
    nlohmann::ordered_json channels = nlohmann::ordered_json::array();
    for (int ch = 0; ch < 3; ++ch) {
        nlohmann::ordered_json points = nlohmann::ordered_json::array();
        for (int i = 0; i < 6; ++i) {
            nlohmann::ordered_json row = nlohmann::ordered_json::array();
            for (int p = 0; p < 10; ++p) row.push_back(c.ctrl[ch][i][p]);
            points.push_back(row);
        }
        channels.push_back(points);
    }
    j["channels"] = channels;
    nlohmann::ordered_json fit = nlohmann::ordered_json::object();
    fit["reference"] = c.reference;
    fit["atmosphere"] = c.atmosphere;
    const nlohmann::ordered_json extra = nlohmann::ordered_json::parse(c.fit_json);
    for (auto it = extra.begin(); it != extra.end(); ++it) {
        if (it.key() != "reference" && it.key() != "atmosphere") fit[it.key()] = it.value();
    }
    j["fit"] = fit;
    return j.dump(2) + "\n";
}

HosekWilkieCoefficients HosekWilkieCoefficientsFromJson(const std::string& text,
                                                        const std::string& source) {
    const std::string where = "hosek-wilkie coefficients " + source;
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
        Fail(where, ": not valid JSON (", e.what(), ")");
    }
    if (!j.is_object()) Fail(where, ": expected a JSON object");
    if (!j.contains("format") || !j["format"].is_string() ||
        j["format"].get<std::string>() != kHosekWilkieCoefficientsFormat) {
        Fail(where, ": field 'format' must be \"", kHosekWilkieCoefficientsFormat,
             "\" (a file written by `atmos fit --model hosek-wilkie`)");
    }
    if (!j.contains("format_version") || !j["format_version"].is_number_integer() ||
        j["format_version"].get<int>() != kHosekWilkieCoefficientsVersion) {
        Fail(where, ": field 'format_version' must be ", kHosekWilkieCoefficientsVersion,
             " (written by another version of atmos: fit again)");
    }
    HosekWilkieCoefficients c;
    if (!j.contains("channels") || !j["channels"].is_array() || j["channels"].size() != 3) {
        Fail(where, ": field 'channels' must be an array of 3 channels");
    }
    for (int ch = 0; ch < 3; ++ch) {
        const nlohmann::json& points = j["channels"][static_cast<size_t>(ch)];
        const std::string at = "channels[" + std::to_string(ch) + "]";
        if (!points.is_array() || points.size() != 6) {
            Fail(where, ": field '", at, "' must be an array of 6 control points");
        }
        for (int i = 0; i < 6; ++i) {
            const nlohmann::json& row = points[static_cast<size_t>(i)];
            const std::string at_i = at + "[" + std::to_string(i) + "]";
            if (!row.is_array() || row.size() != 10) {
                Fail(where, ": field '", at_i,
                     "' must be an array of 10 numbers (A B C D E F G I H L_M)");
            }
            for (int p = 0; p < 10; ++p) {
                const nlohmann::json& v = row[static_cast<size_t>(p)];
                const std::string at_p =
                    at_i + "[" + std::to_string(p) + "] (" + kParameterNames[p] + ")";
                if (!v.is_number() || !std::isfinite(v.get<double>())) {
                    Fail(where, ": field '", at_p, "' must be a finite number");
                }
                const double x = v.get<double>();
                if (p == 9 && x < 0.0) {
                    Fail(where, ": field '", at_p, "' must be >= 0 (a radiance), got ", x);
                }
                c.ctrl[ch][i][p] = x;
            }
        }
    }
    if (!j.contains("fit") || !j["fit"].is_object()) {
        Fail(where, ": field 'fit' must be an object (the reference and atmosphere fitted to)");
    }
    const nlohmann::json& fit = j["fit"];
    for (const char* name : {"reference", "atmosphere"}) {
        if (!fit.contains(name) || !fit[name].is_string() || fit[name].get<std::string>().empty()) {
            Fail(where, ": field 'fit.", name, "' must be a non-empty string");
        }
    }
    c.reference = fit["reference"].get<std::string>();
    c.atmosphere = fit["atmosphere"].get<std::string>();
    c.fit_json = fit.dump();
    return c;
}

HosekWilkieCoefficients LoadHosekWilkieCoefficients(const std::string& path) {
    std::string text;
    try {
        text = ReadFileBounded(path, size_t{1} << 20);
    } catch (const Error& e) {
        Fail("hosek-wilkie coefficients: ", e.what());
    }
    return HosekWilkieCoefficientsFromJson(text, path);
}

}  // namespace atmos
