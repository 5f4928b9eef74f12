// atmos: the factory of a model class, for the registry (models/registry.cpp,
// THE list) and for run-time registration (RegisterModel, atmos/model.h).
//
// A model class M provides `static ModelInfo StaticInfo()`, an options struct O,
// `static const OptionTable<O>& OptionRows()` and a constructor from O: the
// factory parses and validates the user's option text through the table, once,
// and hands the model its typed struct.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "atmos/model.h"

namespace atmos {

template <typename M>
ModelFactory ModelFactoryOf() {
    return {[] { return M::StaticInfo(); },
            [](const std::map<std::string, std::string>& given) {
                return std::unique_ptr<Model>(
                    new M(M::OptionRows().Parse(M::StaticInfo().name, given)));
            },
            [](const std::map<std::string, std::string>& given) {
                return M::OptionRows().Values(M::OptionRows().Parse(M::StaticInfo().name, given));
            }};
}

}  // namespace atmos
