// atmos: option validation and small helpers of the model interface.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/number.h"

namespace atmos {

Quantity ParseQuantity(const std::string& text) {
    if (text == "radiance") return Quantity::kRadiance;
    if (text == "transmittance") return Quantity::kTransmittance;
    Fail("unknown quantity '", text, "' (quantities: radiance, transmittance)");
}

const char* QuantityName(Quantity q) {
    return q == Quantity::kRadiance ? "radiance" : "transmittance";
}

std::string FormatOptionNumber(double value) {
    char buf[40];
    if (value == std::floor(value) && std::fabs(value) < 1e15) {
        std::snprintf(buf, sizeof buf, "%.0f", value);
        return buf;
    }
    for (int precision = 1; precision <= 17; ++precision) {
        std::snprintf(buf, sizeof buf, "%.*g", precision, value);
        if (std::strtod(buf, nullptr) == value) break;
    }
    return buf;
}

const char* ModelOptionSpec::TypeName() const {
    switch (type) {
        case Type::kInteger:
            return "integer";
        case Type::kReal:
            return "real";
        case Type::kChoice:
            return "choice";
        case Type::kText:
            return "text";
    }
    return "?";
}

std::string ModelOptionSpec::Describe() const {
    auto range = [&] {
        return "[" + FormatOptionNumber(min) + ", " + FormatOptionNumber(max) + "]";
    };
    switch (type) {
        case Type::kInteger:
            return "an integer in " + range();
        case Type::kReal:
            return "a number in " + range() + (unit.empty() ? "" : " " + unit);
        case Type::kChoice: {
            std::string list;
            for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
            return "one of " + list;
        }
        case Type::kText:
            return "a non-empty text";
    }
    return "?";
}

std::string OptionsMarkdown(const std::vector<ModelOptionSpec>& specs) {
    if (specs.empty()) return "This model has no options.\n";
    std::string md = "| option | type | default | range | help |\n|---|---|---|---|---|\n";
    for (const ModelOptionSpec& s : specs) {
        std::string range;
        switch (s.type) {
            case ModelOptionSpec::Type::kInteger:
            case ModelOptionSpec::Type::kReal:
                range = "[" + FormatOptionNumber(s.min) + ", " + FormatOptionNumber(s.max) + "]" +
                        (s.unit.empty() ? "" : " " + s.unit);
                break;
            case ModelOptionSpec::Type::kChoice:
                for (const std::string& c : s.choices) range += (range.empty() ? "" : ", ") + c;
                break;
            case ModelOptionSpec::Type::kText:
                range = "non-empty text";
                break;
        }
        std::string help = s.help;
        if (s.shapes_tables) help += " (shapes the baked tables)";
        std::string escaped;
        for (char c : help) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
        md += "| `" + s.name + "` | " + s.TypeName() + " | " +
              (s.default_value.empty() ? std::string("(none)") : "`" + s.default_value + "`") +
              " | " + range + " | " + escaped + " |\n";
    }
    return md;
}

namespace {

bool ParseDouble(const std::string& text, double* value) {
    return ParseNumber(text, value) == NumberError::kNone;  // atmos/number.h
}

[[noreturn]] void FailValue(const std::string& model, const ModelOptionSpec& spec,
                            const std::string& text) {
    Fail("model ", model, ": option ", spec.name, " must be ", spec.Describe(), ", got '", text,
         "'");
}

}  // namespace

namespace detail {

double ParseNumberOption(const std::string& model, const ModelOptionSpec& spec,
                         const std::string& text) {
    double v = 0.0;
    const bool integer = spec.type == ModelOptionSpec::Type::kInteger;
    if (!ParseDouble(text, &v) || (integer && v != std::floor(v)) || v < spec.min || v > spec.max) {
        FailValue(model, spec, text);
    }
    return v;
}

size_t ParseChoiceOption(const std::string& model, const ModelOptionSpec& spec,
                         const std::string& text) {
    for (size_t i = 0; i < spec.choices.size(); ++i) {
        if (spec.choices[i] == text) return i;
    }
    FailValue(model, spec, text);
}

void CheckTextOption(const std::string& model, const ModelOptionSpec& spec,
                     const std::string& text) {
    if (text.empty()) FailValue(model, spec, text);
}

void FailUnknownOption(const std::string& model, const std::vector<ModelOptionSpec>& specs,
                       const std::string& name) {
    std::string list;
    for (const ModelOptionSpec& spec : specs) list += (list.empty() ? "" : ", ") + spec.name;
    Fail("model ", model, " has no option '", name, "'",
         list.empty() ? std::string(" (it takes no options)") : " (its options: " + list + ")",
         "; `atmos list ", model, "` prints them");
}

}  // namespace detail

const OptionTable<NoOptions>& NoOptionTable() {
    static const OptionTable<NoOptions> table;
    return table;
}

ModelSpec ParseModelSpec(const std::string& text) {
    ModelSpec spec;
    spec.text = text;
    size_t at = text.find(':');
    spec.name = GetModelInfo(text.substr(0, at)).name;
    while (at != std::string::npos) {
        const size_t next = text.find(':', at + 1);
        const std::string item =
            text.substr(at + 1, next == std::string::npos ? next : next - at - 1);
        const size_t eq = item.find('=');
        if (eq == std::string::npos || eq == 0) {
            Fail("model '", text, "': expected NAME:OPTION=VALUE[:OPTION=VALUE...], got '", item,
                 "'");
        }
        if (!spec.options.emplace(item.substr(0, eq), item.substr(eq + 1)).second) {
            Fail("model '", text, "': option '", item.substr(0, eq), "' given twice");
        }
        at = next;
    }
    ResolveModelOptions(spec.name, spec.options);  // validates names and values
    return spec;
}

std::unique_ptr<Model> CreateModel(const ModelSpec& spec) {
    return CreateModel(spec.name, spec.options);
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

void Model::PrepareWide(const std::vector<AtmosphereParameters>&, const BatchPrepare&) {
    Fail("model ", Info().name, " has no wide channel batches (capability wide_channels)");
}

void Model::RenderWide(const RenderRequest&, std::vector<float>*) const {
    Fail("model ", Info().name, " has no wide channel batches (capability wide_channels)");
}

std::vector<float> Model::SampleWide(const std::vector<SampleQuery>&) const {
    Fail("model ", Info().name, " has no wide channel batches (capability wide_channels)");
}

void Model::SetSpectralPaths(const SpectralAtmosphere&, const std::vector<double>&) {
    Fail("model ", Info().name, " has no paths that carry many wavelengths");
}

void Model::RenderSpectralPaths(const RenderRequest&, std::vector<float>*) const {
    Fail("model ", Info().name, " has no paths that carry many wavelengths");
}

std::vector<float> Model::SampleSpectralPaths(const std::vector<SampleQuery>&,
                                              const MonteCarloSettings&) const {
    Fail("model ", Info().name, " has no paths that carry many wavelengths");
}

}  // namespace atmos
