// atmos: a model's options in a bake's JSON, from its option table.
//
// `atmos bake` writes every option under "options" (name -> value: integers and
// reals as JSON numbers, choices and text as strings); `--load` checks that the
// model it loads into has the same values (CheckBakedOptions).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "atmos/options.h"

namespace atmos {

// values: OptionTable::Values (name, canonical text), in the specs' order.
nlohmann::ordered_json OptionsJson(const std::vector<ModelOptionSpec>& specs,
                                   const std::vector<std::pair<std::string, std::string>>& values);
// Throws atmos::Error naming `path`, the first option that shapes the tables
// (ModelOptionSpec::shapes_tables) whose baked value differs
// from `values` (or is missing), and both values.
void CheckBakedOptions(const std::string& path, const nlohmann::ordered_json& baked,
                       const std::vector<ModelOptionSpec>& specs,
                       const std::vector<std::pair<std::string, std::string>>& values);

}  // namespace atmos
