#include "models/oneil.h"

#include "atmos/error.h"
#include "physics/analytic_fit.h"
#include "render/wide.h"

namespace atmos {

OneilOptics MakeOneilOptics(const AtmosphereParameters& atmosphere, bool refit) {
    OneilOptics o;
    o.m = MakeAnalyticMedia(atmosphere);
    const double bottom = atmosphere.bottom_radius;
    const double top = atmosphere.top_radius;
    if (refit) {
        o.rayleigh = FitOneilScale(o.m.rayleigh_H, bottom, top);
        o.mie = FitOneilScale(o.m.mie_H, bottom, top);
    } else {
        // O'Neil's single scale depth, 0.25 of the thickness, for both media.
        const double H = 0.25 * (top - bottom);
        o.m.rayleigh_H = H;
        o.m.mie_H = H;
        o.rayleigh = OriginalOneilScale(H, bottom, top);
        o.mie = OriginalOneilScale(H, bottom, top);
    }
    return o;
}

ModelInfo OneilModel::StaticInfo() {
    ModelInfo info;
    info.name = "oneil";
    info.title = "O'Neil 2005 (GPU Gems 2 ch. 16), per pixel";
    info.citation =
        "O'Neil 2005, GPU Gems 2 ch. 16; Raush's O'Neil slides (2018); Leenman's 2025 thesis "
        "section 5.1 (Eq. 17)";
    info.summary =
        "single scattering, midpoint rule with the fitted scale() optical depth; scale() "
        "refitted per atmosphere in Prepare(); no ozone";
    info.capabilities.precomputed = true;
    info.capabilities.wide_channels = true;
    info.options = OptionRows().Specs();
    // Measured: the zenith transmittance from the ground against its own at
    // Earth (docs/models/oneil.md "Validity domain"): -1.3 % at a planet of
    // 1760 column heights, -2.3 % at 2640 (2 % at about 2400), -5.9 % at 8800,
    // T = 1 on the giant planet.
    info.domain.max_radius_heights = 2400.0;
    info.domain.radius_heights_reason =
        "scale() fits the optical depth of an Earth-curved shell: zenith transmittance -2.3 % "
        "at 2640 heights, -5.9 % at 8800, 1 on a 1e9 m planet";
    return info;
}

const OptionTable<OneilOptions>& OneilModel::OptionRows() {
    static const auto table =
        OptionTable<OneilOptions>()
            .Integer("steps", &OneilOptions::steps, 1, 1e5, "", "view-ray samples (his nSamples)")
            .Choice("fit", &OneilOptions::refit, {{"refit", true}, {"original", false}},
                    "scale() constants: refit (least squares per medium) or original (O'Neil's, "
                    "scale depth 0.25)");
    return table;
}

OneilModel::OneilModel(const OneilOptions& options) {
    evaluator_.steps = options.steps;
    refit_ = options.refit;
    Prepare(EarthAtmosphere());
}

void OneilModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.optics = MakeOneilOptics(atmosphere, refit_);
}

void OneilModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                             const BatchPrepare&) {
    // No tables: each batch's Prepare() is its scale() fit and coefficients,
    // made here. The batches share everything but the coefficients
    // (MakeWideCoefficients checks), so the fits are batch 0's.
    wide_ = PreparedWide<OneilWideEvaluator>();
    wide_.coefficients = MakeWideCoefficients(batches);
    for (const AtmosphereParameters& a : batches) WarnOutsideValidityDomain(Info(), a);
    OneilWideEvaluator& e = wide_.evaluator;
    e.narrow = evaluator_;
    e.narrow.optics = MakeOneilOptics(batches[0], refit_);
    e.channels = static_cast<int>(batches.size()) * 3;
    for (size_t b = 0; b < batches.size(); ++b) {
        // MakeOneilOptics's coefficients (its fit changes only scale() and
        // the heights, common to the batches).
        const AnalyticMedia m = MakeAnalyticMedia(batches[b]);
        for (int c = 0; c < 3; ++c) {
            const size_t k = 3 * b + static_cast<size_t>(c);
            e.rayleigh_scattering[k] = m.rayleigh_scattering[c];
            e.mie_scattering[k] = m.mie_scattering[c];
            e.mie_extinction[k] = m.mie_extinction[c];
            e.ground_albedo[k] = m.ground_albedo[c];
        }
    }
    wide_.atmosphere = batches[0];
    wide_.prepared = true;
}

void OneilModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    RenderPreparedWide("oneil", wide_, request, values);
}

std::vector<float> OneilModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    return SamplePreparedWide("oneil", wide_, queries);
}

}  // namespace atmos
