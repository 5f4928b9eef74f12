#include "models/schuler.h"

#include "atmos/error.h"
#include "models/transmittance_chapman.h"
#include "render/wide.h"

namespace atmos {

ModelInfo SchulerModel::StaticInfo() {
    ModelInfo info;
    info.name = "schuler";
    info.title = "Naive integrator with Schuler's Chapman light depth";
    info.citation =
        "Schuler 2012 (GPU Pro 3); Leenman's 2025 thesis sections 5.1 (Eq. 22-25), 11.2.7";
    info.summary =
        "single scattering, view ray by the midpoint rule, light optical depth by the "
        "Chapman approximation; no ozone";
    info.capabilities.wide_channels = true;
    info.options = OptionRows().Specs();
    info.thesis_name = "Schuler";
    info.thesis_lines = 106;
    // Measured: the zenith transmittance from the ground against its own at
    // Earth (docs/models/schuler.md "Validity domain"): +1.8 % at 26.4 column
    // heights, +3.5 % at 35.1, T = 1 on the giant planet.
    info.domain.max_shell_heights = 25.0;
    info.domain.shell_heights_reason =
        "the view ray's midpoint steps span the whole shell and step over the air near the "
        "ground (zenith transmittance +3.5 % at 35 heights, 1 on a 1e9 m shell)";
    return info;
}

const OptionTable<SchulerOptions>& SchulerModel::OptionRows() {
    static const auto table =
        OptionTable<SchulerOptions>()
            .Integer("steps", &SchulerOptions::steps, 1, 1e5, "", "view-ray integration samples")
            .Choice("chapman-unit", &SchulerOptions::chapman_unit, ChapmanUnitChoices(),
                    kChapmanUnitHelp);
    return table;
}

SchulerModel::SchulerModel(const SchulerOptions& options) {
    evaluator_.steps = options.steps;
    evaluator_.chapman_unit = options.chapman_unit;
    Prepare(EarthAtmosphere());
}

void SchulerModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.m = MakeAnalyticMedia(atmosphere);
}

void SchulerModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                               const BatchPrepare&) {
    // No tables: each batch's Prepare() is its atmosphere and its
    // AnalyticMedia, made here; the batches share all but the coefficients
    // (MakeWideCoefficients checks).
    const WideCoefficients coefficients = MakeWideCoefficients(batches);
    for (const AtmosphereParameters& a : batches) WarnOutsideValidityDomain(Info(), a);
    wide_ = PreparedWide<SchulerWideEvaluator>();
    SchulerWideEvaluator& e = wide_.evaluator;
    e.narrow = evaluator_;
    e.narrow.atm = batches[0];
    e.narrow.m = MakeAnalyticMedia(batches[0]);
    e.w = coefficients;
    for (size_t b = 0; b < batches.size(); ++b) {
        const AnalyticMedia m = MakeAnalyticMedia(batches[b]);
        for (int c = 0; c < 3; ++c) {
            e.light_rayleigh[3 * b + static_cast<size_t>(c)] = m.rayleigh_scattering[c];
            e.light_mie[3 * b + static_cast<size_t>(c)] = m.mie_extinction[c];
        }
    }
    wide_.atmosphere = batches[0];
    wide_.coefficients = coefficients;
    wide_.prepared = true;
}

void SchulerModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    RenderPreparedWide("schuler", wide_, request, values);
}

std::vector<float> SchulerModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    return SamplePreparedWide("schuler", wide_, queries);
}

}  // namespace atmos
