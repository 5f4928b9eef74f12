// atmos: the registry of models, built from THE list (models/model_list.h).
#include <functional>
#include <memory>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "models/model_list.h"

namespace atmos {

namespace {

// Each model M provides `static ModelInfo StaticInfo()`, an options struct O,
// `static const OptionTable<O>& OptionRows()` and a constructor from O: the registry parses and
// validates the user's option text through the table, once, and hands the model its typed struct.
struct Entry {
    std::function<ModelInfo()> info;
    std::function<std::unique_ptr<Model>(const std::string&,
                                         const std::map<std::string, std::string>&)>
        create;
    std::function<std::vector<std::pair<std::string, std::string>>(
        const std::string&, const std::map<std::string, std::string>&)>
        resolve;
};

template <typename M>
Entry MakeEntry() {
    return {[] { return M::StaticInfo(); },
            [](const std::string& name, const std::map<std::string, std::string>& given) {
                return std::unique_ptr<Model>(new M(M::OptionRows().Parse(name, given)));
            },
            [](const std::string& name, const std::map<std::string, std::string>& given) {
                return M::OptionRows().Values(M::OptionRows().Parse(name, given));
            }};
}

const std::vector<Entry>& Registry() {
    static const std::vector<Entry> entries = {
#define ATMOS_REGISTRY_ENTRY(M, E) MakeEntry<M>(),
        ATMOS_MODELS(ATMOS_REGISTRY_ENTRY)
#undef ATMOS_REGISTRY_ENTRY
    };
    return entries;
}

const std::vector<ModelInfo>& Infos() {
    static const std::vector<ModelInfo> infos = [] {
        std::vector<ModelInfo> v;
        for (const Entry& e : Registry()) v.push_back(e.info());
        return v;
    }();
    return infos;
}

}  // namespace

ModelInfo EmptyModel::StaticInfo() {
    ModelInfo info;
    info.name = "empty";
    info.title = "Empty (constant white)";
    info.citation = "seed 003 section 11.2.1";
    info.summary = "no physics: the overhead baseline of the render loop";
    return info;
}

std::vector<ModelInfo> ListModels() { return Infos(); }

bool HasDeviceKernels(const std::type_info& evaluator) {
    static const std::vector<std::type_index> listed = {
#define ATMOS_DEVICE_EVALUATOR(M, E) std::type_index(typeid(E)),
        ATMOS_MODELS(ATMOS_DEVICE_EVALUATOR)
#undef ATMOS_DEVICE_EVALUATOR
    };
    for (const std::type_index& t : listed) {
        if (t == std::type_index(evaluator)) return true;
    }
    return false;
}

const ModelInfo& GetModelInfo(const std::string& name) {
    for (const ModelInfo& info : Infos()) {
        if (info.name == name) return info;
    }
    std::string list;
    for (const ModelInfo& info : Infos()) list += (list.empty() ? "" : ", ") + info.name;
    Fail("unknown model '", name, "' (models: ", list, ")");
}

namespace {
const Entry& EntryOf(const std::string& name) {
    const ModelInfo& info = GetModelInfo(name);
    for (size_t i = 0; i < Infos().size(); ++i) {
        if (Infos()[i].name == info.name) return Registry()[i];
    }
    Fail("unknown model '", name, "'");
}
}  // namespace

std::unique_ptr<Model> CreateModel(const std::string& name,
                                   const std::map<std::string, std::string>& options) {
    return EntryOf(name).create(GetModelInfo(name).name, options);
}

std::vector<std::pair<std::string, std::string>> ResolveModelOptions(
    const std::string& name, const std::map<std::string, std::string>& given) {
    return EntryOf(name).resolve(GetModelInfo(name).name, given);
}

}  // namespace atmos
