// atmos: the host adapters that turn an evaluator (physics/ray.h) into a Model.
//
// EvaluatorModel<Derived>: Render and Sample written once, through the loops of
// render/render.h, inside the model's ResidentScope (render/stages.h): on a
// device backend the tables its evaluator names stay on the device between
// renders (a second render uploads nothing). Derived implements
// `Evaluator MakeEvaluator() const` and
// `const AtmosphereParameters& atmosphere() const`; a Derived that builds
// tables in Prepare() opens `ResidentScope scope(&resident_)` there and calls
// scope.Keep(MakeEvaluator()) at its end.
//
// SimpleEvaluatorModel<Derived, Evaluator>: the state most evaluator models
// are: their ModelInfo and one evaluator, handed out by value. It owns the
// atmosphere of the last Prepare() once: in the evaluator's `atm` member when
// the evaluator has one, else in the base (SetAtmosphere / atmosphere()).
#pragma once

#include <type_traits>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "render/render.h"
#include "render/stages.h"

namespace atmos {

template <typename Derived>
class EvaluatorModel : public Model {
  public:
    void Render(const RenderRequest& request, Image* out) const override {
        const Derived& self = static_cast<const Derived&>(*this);
        const PixelSetup setup = MakePixelSetup(request, self.atmosphere());
        out->Resize(request.width, request.height);
        ResidentScope scope(&resident_);
        const auto evaluator = self.MakeEvaluator();
        scope.Keep(evaluator);
        RenderImage(evaluator, setup, out->View(), request.show_progress);
    }
    std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const override {
        const Derived& self = static_cast<const Derived&>(*this);
        ResidentScope scope(&resident_);
        const auto evaluator = self.MakeEvaluator();
        scope.Keep(evaluator);
        return SampleAll(evaluator, self.atmosphere().bottom_radius, queries);
    }

  protected:
    // The device copies of the model's tables (render/stages.h).
    mutable ResidentTables resident_;
};

// True for evaluators with an `atm` member of type AtmosphereParameters.
template <typename E, typename = void>
struct HoldsAtmosphere : std::false_type {};
template <typename E>
struct HoldsAtmosphere<E, std::void_t<decltype(std::declval<E&>().atm)>>
    : std::is_same<std::decay_t<decltype(std::declval<E&>().atm)>, AtmosphereParameters> {};

template <typename Derived, typename Evaluator>
class SimpleEvaluatorModel : public EvaluatorModel<Derived> {
  public:
    const ModelInfo& Info() const override { return info_; }
    Evaluator MakeEvaluator() const { return evaluator_; }
    const AtmosphereParameters& atmosphere() const {
        if constexpr (kInEvaluator) {
            return evaluator_.atm;
        } else {
            return atm_.value;
        }
    }

  protected:
    static constexpr bool kInEvaluator = HoldsAtmosphere<Evaluator>::value;
    SimpleEvaluatorModel() : info_(Derived::StaticInfo()) { SetAtmosphere(EarthAtmosphere()); }
    // The one place the model's atmosphere is stored (Prepare() calls it):
    // warns outside the model's declared ValidityDomain (atmos/model.h).
    void SetAtmosphere(const AtmosphereParameters& atmosphere) {
        WarnOutsideValidityDomain(info_, atmosphere);
        if constexpr (kInEvaluator) {
            evaluator_.atm = atmosphere;
        } else {
            atm_.value = atmosphere;
        }
    }
    ModelInfo info_;
    Evaluator evaluator_;

  private:
    struct NoAtmosphere {};
    struct OwnAtmosphere {
        AtmosphereParameters value;
    };
    std::conditional_t<kInEvaluator, NoAtmosphere, OwnAtmosphere> atm_;
};

}  // namespace atmos
