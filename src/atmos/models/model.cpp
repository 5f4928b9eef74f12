// atmos: option validation and small helpers of the model interface.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

#include "atmos/error.h"
#include "atmos/model.h"

namespace atmos {

Quantity ParseQuantity(const std::string& text) {
    if (text == "radiance") return Quantity::kRadiance;
    if (text == "transmittance") return Quantity::kTransmittance;
    Fail("unknown quantity '", text, "' (quantities: radiance, transmittance)");
}

const char* QuantityName(Quantity q) {
    return q == Quantity::kRadiance ? "radiance" : "transmittance";
}

namespace {

bool ParseDouble(const std::string& text, double* value) {
    if (text.empty()) return false;
    errno = 0;
    char* end = nullptr;
    *value = std::strtod(text.c_str(), &end);
    return errno == 0 && end == text.c_str() + text.size() && std::isfinite(*value);
}

void CheckValue(const std::string& model, const ModelOptionSpec& spec, const std::string& text) {
    const std::string where = "option --" + spec.name + " of model " + model;
    switch (spec.type) {
        case ModelOptionSpec::Type::kInteger: {
            double v = 0.0;
            if (!ParseDouble(text, &v) || v != std::floor(v) || v < spec.min || v > spec.max) {
                Fail(where, " must be an integer in [", spec.min, ", ", spec.max, "], got '", text,
                     "'");
            }
            break;
        }
        case ModelOptionSpec::Type::kReal: {
            double v = 0.0;
            if (!ParseDouble(text, &v) || v < spec.min || v > spec.max) {
                Fail(where, " must be a number in [", spec.min, ", ", spec.max, "], got '", text,
                     "'");
            }
            break;
        }
        case ModelOptionSpec::Type::kChoice: {
            std::string list;
            for (const std::string& c : spec.choices) {
                if (c == text) return;
                list += (list.empty() ? "" : ", ") + c;
            }
            Fail(where, " must be one of ", list, ", got '", text, "'");
        }
        case ModelOptionSpec::Type::kText:
            if (text.empty()) Fail(where, " must not be empty");
            break;
    }
}

}  // namespace

ModelOptions::ModelOptions(const std::string& model_name, const std::vector<ModelOptionSpec>& specs,
                           const std::map<std::string, std::string>& given) {
    for (const ModelOptionSpec& spec : specs) values_[spec.name] = spec.default_value;
    for (const auto& [name, text] : given) {
        bool known = false;
        for (const ModelOptionSpec& spec : specs) {
            if (spec.name != name) continue;
            known = true;
            CheckValue(model_name, spec, text);
        }
        if (!known) {
            std::string list;
            for (const ModelOptionSpec& spec : specs)
                list += (list.empty() ? "--" : ", --") + spec.name;
            Fail("model ", model_name, " has no option --", name,
                 list.empty() ? std::string(" (it takes no options)")
                              : " (its options: " + list + ")");
        }
        values_[name] = text;
        set_[name] = true;
    }
}

void Model::Bake(const std::string&) const {
    Fail("model ", Info().name, " has no precomputed tables to bake");
}

void Model::LoadBaked(const std::string&, const AtmosphereParameters&) {
    Fail("model ", Info().name, " has no precomputed tables to load");
}

void Model::RenderPass(const RenderRequest&, const MonteCarloPass&, Image*, Progress*) const {
    Fail("model ", Info().name, " is not a Monte Carlo model: it renders no passes");
}

std::vector<SampleAnswer> Model::SamplePass(const std::vector<SampleQuery>&,
                                            const MonteCarloPass&) const {
    Fail("model ", Info().name, " is not a Monte Carlo model: it samples no passes");
}

std::string Model::PassKey() const {
    Fail("model ", Info().name, " is not a Monte Carlo model: it has no pass key");
}

int ModelOptions::GetInt(const std::string& name) const {
    return static_cast<int>(std::lround(GetReal(name)));
}

double ModelOptions::GetReal(const std::string& name) const {
    double v = 0.0;
    if (!ParseDouble(GetText(name), &v)) Fail("option --", name, " is not a number");
    return v;
}

const std::string& ModelOptions::GetText(const std::string& name) const {
    auto it = values_.find(name);
    if (it == values_.end()) Fail("internal: no option --", name);
    return it->second;
}

}  // namespace atmos
