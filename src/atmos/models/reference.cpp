#include "models/reference.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
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
            .Integer("spp", &O::spp, 1, 1e9, "", "paths per pixel (per query for sample)")
            .Integer("seed", &O::seed, 0, 4294967295.0, "", "random seed")
            .Integer("max-order", &O::max_order, 0, 1e6, "",
                     "highest scattering order (volume or ground vertices); 0: unlimited")
            .Integer("shells", &O::shells, 1, kMaxReferenceShells, "",
                     "altitude shells of the majorant (1: one global majorant)")
            .Integer("pass-spp", &O::pass_spp, 0, 1e9, "",
                     "paths per pixel per pass (checkpoint and variance granularity); 0: spp/8 "
                     "in [1, 64]. Set it explicitly to extend a checkpointed render to more spp "
                     "with --resume");
    return table;
}

ReferenceModel::ReferenceModel(const ReferenceOptions& options) : info_(StaticInfo()) {
    spp_ = options.spp;
    pass_spp_ = options.pass_spp;
    shell_count_ = options.shells;
    evaluator_.seed = options.seed;
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

namespace {

// Everything that determines a render's passes; a checkpoint resumes only the
// same render.
nlohmann::json CheckpointKey(const RenderRequest& request, const ReferenceEvaluator& e,
                             int pass_spp) {
    nlohmann::json key;
    key["format"] = "atmos-reference-checkpoint-1";
    key["view"] = request.view.name;
    key["camera"] = {request.view.camera.position.x,    request.view.camera.position.y,
                     request.view.camera.position.z,    request.view.camera.forward.x,
                     request.view.camera.forward.y,     request.view.camera.forward.z,
                     request.view.camera.tan_half_fov_y};
    key["sun"] = {request.view.sun_direction.x, request.view.sun_direction.y,
                  request.view.sun_direction.z};
    key["irradiance"] = request.view.sun_irradiance;
    key["width"] = request.width;
    key["height"] = request.height;
    key["quantity"] = QuantityName(request.quantity);
    key["sun_disc"] = request.sun_disc;
    key["seed"] = e.seed;
    key["max_order"] = e.max_order;
    key["estimator"] = e.spectral ? "spectral" : "thesis";
    key["sun_cone_cos"] = e.sun_cone_cos;
    key["shells"] = e.shells.count;
    key["pass_spp"] = pass_spp;
    key["atmosphere"] = nlohmann::json::parse(AtmosphereToJson(e.atm));
    return key;
}

}  // namespace

void ReferenceModel::Render(const RenderRequest& request, Image* out) const {
    const PixelSetup setup = MakePixelSetup(request, evaluator_.atm);
    out->Resize(request.width, request.height);
    if (request.quantity == Quantity::kTransmittance) {
        // Deterministic: one pass with one sample is enough (T does not depend on it).
        ReferenceEvaluator e = evaluator_;
        e.sample_count = 0;
        RenderImage(e, setup, out->View(), request.show_progress);
        if (request.variance) request.variance->Resize(request.width, request.height);
        return;
    }
    // Passes of pass_spp samples (auto: 8 passes, so the variance of the mean
    // can be estimated from the pass means).
    const int pass_spp = pass_spp_ > 0 ? pass_spp_ : std::clamp(spp_ / 8, 1, 64);
    const int passes = (spp_ + pass_spp - 1) / pass_spp;
    const size_t n = out->size();
    Image sum(request.width, request.height), sum_sq(request.width, request.height);
    int passes_done = 0;
    int samples_done = 0;

    const nlohmann::json key = CheckpointKey(request, evaluator_, pass_spp);
    const std::string stem = request.checkpoint;
    if (!stem.empty() && request.resume && std::filesystem::exists(stem + ".json")) {
        std::ifstream f(stem + ".json");
        nlohmann::json saved;
        try {
            f >> saved;
        } catch (const std::exception& ex) {
            Fail("checkpoint '", stem, ".json' is unreadable: ", ex.what());
        }
        if (!saved.contains("key") || saved["key"] != key) {
            Fail("checkpoint '", stem,
                 ".json' was made for a different render (view, size, seed, atmosphere, "
                 "pass size or order differ); remove it or drop --resume");
        }
        passes_done = saved.value("passes_done", 0);
        samples_done = saved.value("samples_done", 0);
        if (passes_done > passes || samples_done > spp_) {
            Fail("checkpoint '", stem, "' already holds ", samples_done,
                 " samples per pixel, more than --spp ", spp_);
        }
        sum = ReadImage(stem + ".sum.exr");
        sum_sq = ReadImage(stem + ".sumsq.exr");
        if (sum.width() != request.width || sum.height() != request.height ||
            sum_sq.width() != request.width || sum_sq.height() != request.height) {
            Fail("checkpoint '", stem, "' images do not match the render size");
        }
    }
    auto save_checkpoint = [&]() {
        if (stem.empty()) return;
        const std::filesystem::path parent = std::filesystem::path(stem).parent_path();
        if (!parent.empty()) std::filesystem::create_directories(parent);
        WriteImage(sum, stem + ".sum.exr");
        WriteImage(sum_sq, stem + ".sumsq.exr");
        nlohmann::json saved;
        saved["key"] = key;
        saved["passes_done"] = passes_done;
        saved["samples_done"] = samples_done;
        const std::string tmp = stem + ".json.tmp";
        {
            std::ofstream f(tmp);
            f << saved.dump(1) << "\n";
            if (!f) Fail("cannot write checkpoint '", tmp, "'");
        }
        std::filesystem::rename(tmp, stem + ".json");
    };

    const int64_t pixels = static_cast<int64_t>(request.width) * request.height;
    Progress progress("reference", pixels * std::max(passes - passes_done, 1),
                      request.show_progress);
    Image pass(request.width, request.height);
    auto last_save = std::chrono::steady_clock::now();
    for (int p = passes_done; p < passes; ++p) {
        ReferenceEvaluator e = evaluator_;
        e.sample_begin = p * pass_spp;
        e.sample_count = std::min(pass_spp, spp_ - e.sample_begin);
        e.need_transmittance = request.sun_disc;  // the only use of T in a radiance pass
        RenderImage(e, setup, pass.View(), &progress);
        // Weighted by the pass's sample count so a short last pass counts right.
        const float wgt = static_cast<float>(e.sample_count);
        for (size_t i = 0; i < n; ++i) {
            const float v = pass.data()[i];
            sum.data()[i] += wgt * v;
            sum_sq.data()[i] += wgt * v * v;
        }
        ++passes_done;
        samples_done += e.sample_count;
        const auto now = std::chrono::steady_clock::now();
        if (std::chrono::duration<double>(now - last_save).count() > 10.0 || p + 1 == passes) {
            save_checkpoint();
            last_save = now;
        }
    }
    // Mean, and the variance of the mean from the pass means (batch means):
    // Var(mean) = (E[v^2] - mean^2) / (passes - 1), weights by sample count.
    if (request.variance) request.variance->Resize(request.width, request.height);
    const float inv = 1.0f / static_cast<float>(std::max(samples_done, 1));
    for (size_t i = 0; i < n; ++i) {
        const float mean = sum.data()[i] * inv;
        out->data()[i] = mean;
        if (request.variance) {
            const float second = sum_sq.data()[i] * inv;
            const float var = passes_done > 1 ? std::max(second - mean * mean, 0.0f) /
                                                    static_cast<float>(passes_done - 1)
                                              : 0.0f;
            request.variance->data()[i] = var;
        }
    }
}

std::vector<SampleAnswer> ReferenceModel::Sample(const std::vector<SampleQuery>& queries) const {
    ReferenceEvaluator e = evaluator_;
    e.sample_begin = 0;
    e.sample_count = spp_;
    return SampleAll(e, e.atm.bottom_radius, queries);
}

}  // namespace atmos
