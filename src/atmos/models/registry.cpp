// atmos: THE list of models. Adding a model = one entry here.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "models/atmosphere_plus.h"
#include "models/bruneton.h"
#include "models/empty.h"
#include "models/flat.h"
#include "models/hillaire.h"
#include "models/naive.h"
#include "models/neural.h"
#include "models/oneil.h"
#include "models/preetham.h"
#include "models/raymarched.h"
#include "models/reference.h"
#include "models/schuler.h"
#include "models/transmittance_chapman.h"
#include "models/transmittance_erfc.h"
#include "models/transmittance_flat.h"
#include "models/transmittance_oneil.h"
#include "models/transmittance_polynomial.h"
#include "models/transmittance_reference.h"

namespace atmos {

namespace {

// Each model M provides `static ModelInfo StaticInfo()`, its options struct
// (`M::Options`), `static const OptionTable<M::Options>& OptionRows()` and a
// constructor from M::Options: the registry parses and validates the user's
// option text through the table, once, and hands the model its typed struct.
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
        MakeEntry<EmptyModel>(),
        MakeEntry<NaiveModel>(),
        MakeEntry<ReferenceModel>(),
        MakeEntry<OneilModel>(),
        MakeEntry<SchulerModel>(),
        MakeEntry<FlatModel>(),
        MakeEntry<RaymarchedModel>(),
        MakeEntry<PreethamModel>(),
        MakeEntry<TransmittanceReferenceModel>(),
        MakeEntry<TransmittanceFlatModel>(),
        MakeEntry<TransmittanceErfcModel>(),
        MakeEntry<TransmittanceChapmanModel>(),
        MakeEntry<TransmittanceOneilModel>(),
        MakeEntry<TransmittancePolynomialModel>(),
        MakeEntry<HillaireModel>(),
        MakeEntry<BrunetonModel>(),
        MakeEntry<AtmospherePlusModel>(),
        MakeEntry<NeuralModel>(),
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
