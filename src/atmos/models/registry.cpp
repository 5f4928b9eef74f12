// atmos: the registry of models, built from THE list (models/model_list.h).
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "models/model_factory.h"
#include "models/model_list.h"

namespace atmos {

namespace {

struct Entry {
    ModelInfo info;
    ModelFactory factory;
    bool runtime = false;  // RegisterModel
};

// A deque: references to an entry's info (GetModelInfo) stay valid while
// others are appended or removed at the end.
std::deque<Entry>& Registry() {
    static std::deque<Entry> entries = [] {
        std::deque<Entry> v;
        const ModelFactory listed[] = {
#define ATMOS_REGISTRY_ENTRY(M, E) ModelFactoryOf<M>(),
            ATMOS_MODELS(ATMOS_REGISTRY_ENTRY)
#undef ATMOS_REGISTRY_ENTRY
        };
        for (const ModelFactory& f : listed) v.push_back({f.info(), f, false});
        return v;
    }();
    return entries;
}

}  // namespace

ModelInfo EmptyModel::StaticInfo() {
    ModelInfo info;
    info.name = "empty";
    info.title = "Empty (constant white)";
    info.citation = "Leenman's 2025 thesis section 11.2.1";
    info.summary = "no physics: the overhead baseline of the render loop";
    info.capabilities.baseline = true;
    return info;
}

std::vector<ModelInfo> ListModels() {
    std::vector<ModelInfo> v;
    for (const Entry& e : Registry()) v.push_back(e.info);
    return v;
}

void RegisterModel(const ModelFactory& factory) {
    ModelInfo info = factory.info();
    for (const Entry& e : Registry()) {
        if (e.info.name == info.name) Fail("model '", info.name, "' is already registered");
    }
    Registry().push_back({std::move(info), factory, true});
}

void UnregisterModel(const std::string& name) {
    std::deque<Entry>& r = Registry();
    for (auto it = r.begin(); it != r.end(); ++it) {
        if (it->info.name != name) continue;
        if (!it->runtime) Fail("model '", name, "' is in THE list (models/model_list.h)");
        r.erase(it);
        return;
    }
    Fail("unknown model '", name, "'");
}

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

namespace {
const Entry& EntryOf(const std::string& name) {
    for (const Entry& e : Registry()) {
        if (e.info.name == name) return e;
    }
    std::string list;
    for (const Entry& e : Registry()) list += (list.empty() ? "" : ", ") + e.info.name;
    Fail("unknown model '", name, "' (models: ", list, ")");
}
}  // namespace

const ModelInfo& GetModelInfo(const std::string& name) { return EntryOf(name).info; }

std::unique_ptr<Model> CreateModel(const std::string& name,
                                   const std::map<std::string, std::string>& options) {
    return EntryOf(name).factory.create(options);
}

std::vector<std::pair<std::string, std::string>> ResolveModelOptions(
    const std::string& name, const std::map<std::string, std::string>& given) {
    return EntryOf(name).factory.resolve(given);
}

}  // namespace atmos
