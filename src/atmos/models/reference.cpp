#include "models/reference.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "atmos/error.h"

namespace atmos {

namespace {

// Maximum of one layer's unclamped density over [h0, h1]: the end points and
// the critical point of a e^(s h) + l h + c (where a s e^(s h) = -l).
double MaxLayerDensity(const DensityProfileLayer& layer, double h0, double h1) {
    auto f = [&](double h) {
        return layer.exp_term * std::exp(layer.exp_scale * h) + layer.linear_term * h +
               layer.constant_term;
    };
    double m = std::max(f(h0), f(h1));
    const double as = layer.exp_term * layer.exp_scale;
    if (as != 0.0 && layer.exp_scale != 0.0) {
        const double ratio = -layer.linear_term / as;
        if (ratio > 0.0) {
            const double h = std::log(ratio) / layer.exp_scale;
            if (h > h0 && h < h1) m = std::max(m, f(h));
        }
    }
    return m;
}

}  // namespace

double MaxProfileDensity(const DensityProfile& profile, double h0, double h1) {
    const double w = profile.layers[0].width;
    double m = 0.0;
    if (h0 < w) m = std::max(m, MaxLayerDensity(profile.layers[0], h0, std::min(h1, w)));
    if (h1 >= w) m = std::max(m, MaxLayerDensity(profile.layers[1], std::max(h0, w), h1));
    return std::clamp(m, 0.0, 1.0);
}

MajorantShells BuildMajorantShells(const AtmosphereParameters& atm, int count) {
    MajorantShells shells;
    shells.count = std::clamp(count, 1, kMaxReferenceShells);
    const double delta = atm.top_radius - atm.bottom_radius;
    for (int k = 0; k <= shells.count; ++k) {
        const double x = static_cast<double>(k) / shells.count;
        shells.radius[k] = atm.bottom_radius + delta * x * x;
    }
    shells.radius[shells.count] = atm.top_radius;
    for (int k = 0; k < shells.count; ++k) {
        const double h0 = shells.radius[k] - atm.bottom_radius;
        const double h1 = shells.radius[k + 1] - atm.bottom_radius;
        const double mr = MaxProfileDensity(atm.rayleigh_density, h0, h1);
        const double mm = MaxProfileDensity(atm.mie_density, h0, h1);
        const double mo = MaxProfileDensity(atm.absorption_density, h0, h1);
        double bar = 0.0;
        for (int c = 0; c < 3; ++c) {
            bar = std::max(bar, atm.rayleigh_scattering[c] * mr + atm.mie_extinction[c] * mm +
                                    atm.absorption_extinction[c] * mo);
        }
        // A hair above the exact maximum so rounding never makes sigma_n < 0.
        shells.majorant[k] = bar * (1.0 + 1e-9);
    }
    return shells;
}

ModelInfo ReferenceModel::StaticInfo() {
    ModelInfo info;
    info.name = "reference";
    info.title = "Reference path tracer (spectral tracking)";
    info.citation =
        "seed 003 sections 3.2, 4, 11.2.2; Kutz et al. 2017 (spectral tracking); Novak et al. "
        "2014 (ratio tracking)";
    info.summary = "unbiased Monte Carlo: all scattering orders, planet shadow, Lambertian ground";
    info.capabilities.multiple_scattering = true;
    info.capabilities.stochastic = true;
    info.options = OptionRows().Specs();
    return info;
}

const OptionTable<ReferenceOptions>& ReferenceModel::OptionRows() {
    using O = ReferenceOptions;
    static const auto table =
        OptionTable<O>()
            .Integer("sun-disc-light", &O::sun_disc_light, 0, 1, "",
                     "1: light from the sun's disc (angular radius from the atmosphere), sampled "
                     "per next-event estimate; 0: a directional sun like the other models")
            .Choice("estimator", &O::spectral, {{"spectral", true}, {"thesis", false}},
                    "spectral: all channels per path (spectral tracking, forced first collision, "
                    "ratio-tracked sun); thesis: the thesis's estimator (one random channel per "
                    "path, delta tracking, uniform directions), kept as a baseline")
            .Integer("max-order", &O::max_order, 0, 1e6, "",
                     "highest scattering order (volume or ground vertices); 0: unlimited")
            .Integer("shells", &O::shells, 1, kMaxReferenceShells, "",
                     "altitude shells of the majorant (1: one global majorant)");
    return table;
}

ReferenceModel::ReferenceModel(const ReferenceOptions& options) : info_(StaticInfo()) {
    shell_count_ = options.shells;
    evaluator_.max_order = options.max_order;
    evaluator_.spectral = options.spectral;
    sun_disc_light_ = options.sun_disc_light != 0;
    Prepare(EarthAtmosphere());
}

void ReferenceModel::Prepare(const AtmosphereParameters& atmosphere) {
    evaluator_.atm = atmosphere;
    evaluator_.sun_cone_cos = sun_disc_light_ ? std::cos(atmosphere.sun_angular_radius) : 1.0;
    evaluator_.shells = BuildMajorantShells(atmosphere, shell_count_);
}

std::string ReferenceModel::PassKey() const {
    nlohmann::json key;
    key["max_order"] = evaluator_.max_order;
    key["estimator"] = evaluator_.spectral ? "spectral" : "thesis";
    key["sun_cone_cos"] = evaluator_.sun_cone_cos;
    key["shells"] = evaluator_.shells.count;
    key["atmosphere"] = nlohmann::json::parse(AtmosphereToJson(evaluator_.atm));
    return key.dump();
}

void ReferenceModel::RenderPass(const RenderRequest& request, const MonteCarloPass& pass,
                                Image* out, Progress* progress) const {
    const PixelSetup setup = MakePixelSetup(request, evaluator_.atm);
    out->Resize(request.width, request.height);
    ReferenceEvaluator e = evaluator_;
    e.seed = pass.seed;
    if (request.quantity == Quantity::kTransmittance) {
        // Deterministic: no paths needed (T does not depend on them).
        e.sample_count = 0;
    } else {
        e.sample_begin = pass.first_sample;
        e.sample_count = pass.samples;
        e.need_transmittance = request.sun_disc;  // the only use of T in a radiance pass
    }
    RenderImage(e, setup, out->View(), progress);
}

std::vector<SampleAnswer> ReferenceModel::SamplePass(const std::vector<SampleQuery>& queries,
                                                     const MonteCarloPass& pass) const {
    ReferenceEvaluator e = evaluator_;
    e.seed = pass.seed;
    e.sample_begin = pass.first_sample;
    e.sample_count = pass.samples;
    return SampleAll(e, e.atm.bottom_radius, queries);
}

}  // namespace atmos
