#include "models/option_json.h"

#include <cstdlib>

#include "atmos/error.h"

namespace atmos {

nlohmann::ordered_json OptionsJson(const std::vector<ModelOptionSpec>& specs,
                                   const std::vector<std::pair<std::string, std::string>>& values) {
    nlohmann::ordered_json j = nlohmann::ordered_json::object();
    for (size_t i = 0; i < specs.size() && i < values.size(); ++i) {
        const std::string& text = values[i].second;
        switch (specs[i].type) {
            case ModelOptionSpec::Type::kInteger:
                j[values[i].first] = std::strtoll(text.c_str(), nullptr, 10);
                break;
            case ModelOptionSpec::Type::kReal:
                j[values[i].first] = std::strtod(text.c_str(), nullptr);
                break;
            case ModelOptionSpec::Type::kChoice:
            case ModelOptionSpec::Type::kText:
                j[values[i].first] = text;
                break;
        }
    }
    return j;
}

void CheckBakedOptions(const std::string& path, const nlohmann::ordered_json& baked,
                       const std::vector<ModelOptionSpec>& specs,
                       const std::vector<std::pair<std::string, std::string>>& values) {
    const nlohmann::ordered_json all = OptionsJson(specs, values);
    nlohmann::ordered_json want = nlohmann::ordered_json::object();
    for (const ModelOptionSpec& spec : specs) {
        if (spec.shapes_tables) want[spec.name] = all.at(spec.name);
    }
    for (auto it = want.begin(); it != want.end(); ++it) {
        if (!baked.is_object() || !baked.contains(it.key()) || baked.at(it.key()) != it.value()) {
            const bool present = baked.is_object() && baked.contains(it.key());
            Fail("'", path, "' was baked with ", it.key(), " = ",
                 present ? baked.at(it.key()).dump() : std::string("(missing)"),
                 ", but the model has ", it.value().dump());
        }
    }
}

}  // namespace atmos
