// atmos model `neural`: weights as JSON, the shipped weights, options, Prepare.
#include "models/neural.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "atmos/embedded_presets.h"
#include "atmos/error.h"
#include "io/bounded_read.h"

namespace atmos {

namespace {

constexpr const char* kFormat = "atmos-neural-1";

using json = nlohmann::json;

template <typename Net>
json NetToJson(const Net& net) {
    json j;
    std::vector<int> layers;
    for (int l = 0; l <= net.hidden_layers + 1; ++l) layers.push_back(net.Width(l));
    j["layers"] = layers;
    j["output"] = net.output == NeuralOutput::kSigmoid ? "sigmoid" : "exp-neg";
    json w = json::array();
    json b = json::array();
    int w_off = 0;
    int b_off = 0;
    for (int l = 0; l <= net.hidden_layers; ++l) {
        const int n_in = net.Width(l);
        const int n_out = net.Width(l + 1);
        json wl = json::array();
        for (int o = 0; o < n_out; ++o) {
            json row = json::array();
            for (int i = 0; i < n_in; ++i) row.push_back(net.weights[w_off + o * n_in + i]);
            wl.push_back(row);
        }
        json bl = json::array();
        for (int o = 0; o < n_out; ++o) bl.push_back(net.biases[b_off + o]);
        w.push_back(wl);
        b.push_back(bl);
        w_off += n_in * n_out;
        b_off += n_out;
    }
    j["weights"] = w;
    j["biases"] = b;
    return j;
}

double FiniteDouble(const json& v, const std::string& where) {
    if (!v.is_number()) Fail(where, ": expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::fabs(d) > 1e30) Fail(where, ": not a finite number");
    return d;
}
float Finite(const json& v, const std::string& where) {
    return static_cast<float>(FiniteDouble(v, where));
}

template <int MaxIn, int MaxHidden>
NeuralNet<MaxIn, MaxHidden> NetFromJson(const json& j, const std::string& where, int inputs,
                                        NeuralOutput output, int max_hidden_layers) {
    NeuralNet<MaxIn, MaxHidden> net;
    if (!j.is_object()) Fail(where, ": expected an object");
    if (!j.contains("layers") || !j["layers"].is_array()) Fail(where, ".layers: missing");
    const json& layers = j["layers"];
    const int n = static_cast<int>(layers.size());
    if (n < 3 || n > 2 + max_hidden_layers) {
        Fail(where, ".layers: expected 1 to ", max_hidden_layers, " hidden layers, got ", n - 2);
    }
    std::vector<int> widths;
    for (const json& v : layers) {
        if (!v.is_number_integer()) Fail(where, ".layers: expected integers");
        widths.push_back(v.get<int>());
    }
    if (widths.front() != inputs) {
        Fail(where, ".layers: the network takes ", widths.front(), " inputs, the encoding gives ",
             inputs);
    }
    if (widths.back() != kNeuralOutputs) Fail(where, ".layers: expected 3 outputs");
    for (int l = 1; l + 1 < n; ++l) {
        if (widths[l] < 1 || widths[l] > MaxHidden) {
            Fail(where, ".layers: hidden width ", widths[l], " outside [1, ", MaxHidden, "]");
        }
    }
    net.inputs = inputs;
    net.hidden_layers = n - 2;
    for (int l = 1; l + 1 < n; ++l) net.hidden[l - 1] = widths[l];
    const std::string out = j.value("output", "");
    const std::string want = output == NeuralOutput::kSigmoid ? "sigmoid" : "exp-neg";
    if (out != want) Fail(where, ".output: expected '", want, "', got '", out, "'");
    net.output = output;
    if (!j.contains("weights") || !j["weights"].is_array() || !j.contains("biases") ||
        !j["biases"].is_array() || static_cast<int>(j["weights"].size()) != n - 1 ||
        static_cast<int>(j["biases"].size()) != n - 1) {
        Fail(where, ": expected ", n - 1, " weight matrices and bias vectors");
    }
    int w_off = 0;
    int b_off = 0;
    for (int l = 0; l + 1 < n; ++l) {
        const json& wl = j["weights"][static_cast<size_t>(l)];
        const json& bl = j["biases"][static_cast<size_t>(l)];
        const std::string wl_where = where + ".weights[" + std::to_string(l) + "]";
        if (!wl.is_array() || static_cast<int>(wl.size()) != widths[l + 1]) {
            Fail(wl_where, ": expected ", widths[l + 1], " rows");
        }
        if (!bl.is_array() || static_cast<int>(bl.size()) != widths[l + 1]) {
            Fail(where, ".biases[", l, "]: expected ", widths[l + 1], " values");
        }
        for (int o = 0; o < widths[l + 1]; ++o) {
            const json& row = wl[static_cast<size_t>(o)];
            if (!row.is_array() || static_cast<int>(row.size()) != widths[l]) {
                Fail(wl_where, "[", o, "]: expected ", widths[l], " values");
            }
            for (int i = 0; i < widths[l]; ++i) {
                net.weights[w_off + o * widths[l] + i] =
                    Finite(row[static_cast<size_t>(i)], wl_where);
            }
            net.biases[b_off + o] = Finite(bl[static_cast<size_t>(o)], where + ".biases");
        }
        w_off += widths[l] * widths[l + 1];
        b_off += widths[l + 1];
    }
    return net;
}

Vec3d Vec3FromJson(const json& j, const std::string& where) {
    if (!j.is_array() || j.size() != 3) Fail(where, ": expected 3 numbers");
    return Vec3d(FiniteDouble(j[0], where), FiniteDouble(j[1], where), FiniteDouble(j[2], where));
}

bool Close(double a, double b) {
    return std::fabs(a - b) <= 1e-6 * std::fmax(std::fabs(a), std::fabs(b)) + 1e-30;
}
bool Close(const Vec3d& a, const Vec3d& b) {
    return Close(a.x, b.x) && Close(a.y, b.y) && Close(a.z, b.z);
}

}  // namespace

const char* NeuralEncodingName(NeuralEncoding encoding) {
    switch (encoding) {
        case NeuralEncoding::kThesis:
            return "thesis";
        case NeuralEncoding::kExtended:
            return "extended";
        case NeuralEncoding::kHorizon:
            return "horizon";
    }
    return "thesis";
}

bool ParseNeuralEncoding(const std::string& name, NeuralEncoding* encoding) {
    for (NeuralEncoding e :
         {NeuralEncoding::kThesis, NeuralEncoding::kExtended, NeuralEncoding::kHorizon}) {
        if (name == NeuralEncodingName(e)) {
            *encoding = e;
            return true;
        }
    }
    return false;
}

NeuralWeights NeuralWeightsFromJson(const std::string& text, const std::string& source) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        Fail("neural weights ", source, ": not valid JSON (", e.what(), ")");
    }
    try {
        if (!j.is_object() || j.value("format", "") != kFormat) {
            Fail("expected \"format\": \"", kFormat, "\"");
        }
        NeuralWeights w;
        const std::string enc = j.value("encoding", "");
        if (!ParseNeuralEncoding(enc, &w.encoding)) {
            Fail("encoding: expected 'thesis', 'extended' or 'horizon', got '", enc, "'");
        }
        if (!j.contains("atmosphere") || !j["atmosphere"].is_object()) Fail("atmosphere: missing");
        const json& a = j["atmosphere"];
        if (!a.contains("bottom_radius") || !a.contains("top_radius") ||
            !a.contains("mie_phase_g")) {
            Fail("atmosphere: expected bottom_radius, top_radius, mie_phase_g, ...");
        }
        w.bottom_radius = FiniteDouble(a["bottom_radius"], "atmosphere.bottom_radius");
        w.top_radius = FiniteDouble(a["top_radius"], "atmosphere.top_radius");
        w.mie_phase_g = FiniteDouble(a["mie_phase_g"], "atmosphere.mie_phase_g");
        if (!(w.top_radius > w.bottom_radius && w.bottom_radius > 0.0)) {
            Fail("atmosphere: need 0 < bottom_radius < top_radius");
        }
        w.rayleigh_scattering =
            Vec3FromJson(a.value("rayleigh_scattering", json()), "atmosphere.rayleigh_scattering");
        w.mie_scattering =
            Vec3FromJson(a.value("mie_scattering", json()), "atmosphere.mie_scattering");
        w.mie_extinction =
            Vec3FromJson(a.value("mie_extinction", json()), "atmosphere.mie_extinction");
        w.absorption_extinction = Vec3FromJson(a.value("absorption_extinction", json()),
                                               "atmosphere.absorption_extinction");
        if (j.contains("fit_atmosphere")) {
            if (!j["fit_atmosphere"].is_object()) Fail("fit_atmosphere: expected an object");
            w.fit_atmosphere = AtmosphereFromJson(j["fit_atmosphere"].dump(), "fit_atmosphere");
            w.has_fit_atmosphere = true;
        }
        if (!j.contains("transmittance")) Fail("transmittance: missing");
        if (!j.contains("scattering")) Fail("scattering: missing");
        w.transmittance =
            NetFromJson<4, 16>(j["transmittance"], "transmittance",
                               NeuralTransmittanceInputs(w.encoding), NeuralOutput::kSigmoid, 2);
        w.scattering = NetFromJson<kNeuralMaxInputs, kNeuralMaxHidden>(
            j["scattering"], "scattering", NeuralScatteringInputs(w.encoding),
            NeuralOutput::kExpNeg, kNeuralMaxHiddenLayers);
        if (j.contains("training")) w.training_json = j["training"].dump();
        return w;
    } catch (const Error& e) {
        Fail("neural weights ", source, ": ", e.what());
    } catch (const json::exception& e) {
        Fail("neural weights ", source, ": ", e.what());
    }
}

std::string NeuralWeightsToJson(const NeuralWeights& w) {
    json j;
    j["format"] = kFormat;
    j["encoding"] = NeuralEncodingName(w.encoding);
    json a;
    a["bottom_radius"] = w.bottom_radius;
    a["top_radius"] = w.top_radius;
    a["mie_phase_g"] = w.mie_phase_g;
    auto v3 = [](const Vec3d& v) { return json::array({v.x, v.y, v.z}); };
    a["rayleigh_scattering"] = v3(w.rayleigh_scattering);
    a["mie_scattering"] = v3(w.mie_scattering);
    a["mie_extinction"] = v3(w.mie_extinction);
    a["absorption_extinction"] = v3(w.absorption_extinction);
    j["atmosphere"] = a;
    if (w.has_fit_atmosphere) j["fit_atmosphere"] = json::parse(AtmosphereToJson(w.fit_atmosphere));
    j["transmittance"] = NetToJson(w.transmittance);
    j["scattering"] = NetToJson(w.scattering);
    j["training"] = json::parse(w.training_json);
    return j.dump(1) + "\n";
}

NeuralWeights LoadNeuralWeights(const std::string& path) {
    RequireRegularInput(path, "neural weights");  // a FIFO no one writes would block the open
    std::ifstream in(path, std::ios::binary);
    if (!in) Fail("neural weights: cannot open '", path, "'");
    std::stringstream ss;
    ss << in.rdbuf();
    return NeuralWeightsFromJson(ss.str(), "'" + path + "'");
}

NeuralWeights EmbeddedNeuralWeights(const std::string& name) {
    for (const detail::EmbeddedPreset* e = detail::kEmbeddedNeuralWeights; e->name; ++e) {
        if (name == e->name) return NeuralWeightsFromJson(e->json, "data/neural/" + name + ".json");
    }
    Fail("neural: no shipped weights named '", name, "' (data/neural/", name, ".json)");
}

void CheckNeuralSingleMieLobe(const AtmosphereParameters& a) {
    if (a.mie_phase_kind != MiePhaseKind::kCornetteShanks) {
        Fail("neural: the atmosphere's mie_phase is ", MiePhaseKindName(a.mie_phase_kind),
             ": the network's input encoding carries one Cornette-Shanks lobe (mie_phase_g), so "
             "neural takes only the cornette-shanks kind");
    }
    if (a.mie_phase_weight2 != 0.0) {
        Fail("neural: the atmosphere's mie_phase_weight2 is ", a.mie_phase_weight2,
             ": the network's input encoding carries one Cornette-Shanks lobe (mie_phase_g), so "
             "neural takes only mie_phase_weight2 = 0");
    }
}

void CheckNeuralWeightsMatch(const NeuralWeights& w, const AtmosphereParameters& a,
                             const std::string& source) {
    const char* fix =
        "; fit new ones with `atmos fit --model neural --atmosphere ... [--set ...] -o FILE.json` "
        "and pass --weights FILE.json";
    if (!w.has_fit_atmosphere) {
        Fail("neural weights ", source,
             " do not record the whole atmosphere they were fitted to (no \"fit_atmosphere\": "
             "written before atmos checked ground albedo and density profiles)",
             fix);
    }
    // Every field the fit depends on: the reference the networks were fitted
    // to saw all of them (ground albedo through the ground's light in the
    // higher orders, sun_angular_radius through the sun's disc at the horizon,
    // mu_s_min through the precomputed tables); solar_irradiance only scales
    // the output.
    const AtmosphereParameters& f = w.fit_atmosphere;
    std::string differ;
    auto add = [&differ](const char* name) {
        differ += (differ.empty() ? "" : ", ") + std::string(name);
    };
    auto same_profile = [](const DensityProfile& x, const DensityProfile& y) {
        for (int l = 0; l < 2; ++l) {
            const DensityProfileLayer& p = x.layers[l];
            const DensityProfileLayer& q = y.layers[l];
            if (!Close(p.width, q.width) || !Close(p.exp_term, q.exp_term) ||
                !Close(p.exp_scale, q.exp_scale) || !Close(p.linear_term, q.linear_term) ||
                !Close(p.constant_term, q.constant_term)) {
                return false;
            }
        }
        return true;
    };
    if (!Close(f.bottom_radius, a.bottom_radius)) add("bottom_radius");
    if (!Close(f.top_radius, a.top_radius)) add("top_radius");
    if (!Close(f.rayleigh_scattering, a.rayleigh_scattering)) add("rayleigh_scattering");
    if (!same_profile(f.rayleigh_density, a.rayleigh_density)) add("rayleigh_density");
    if (!Close(f.mie_scattering, a.mie_scattering)) add("mie_scattering");
    if (!Close(f.mie_extinction, a.mie_extinction)) add("mie_extinction");
    if (!same_profile(f.mie_density, a.mie_density)) add("mie_density");
    if (!Close(f.mie_phase_g, a.mie_phase_g)) add("mie_phase_g");
    if (!Close(f.absorption_extinction, a.absorption_extinction)) add("absorption_extinction");
    if (!same_profile(f.absorption_density, a.absorption_density)) add("absorption_density");
    if (!Close(f.ground_albedo, a.ground_albedo)) add("ground_albedo");
    if (!Close(f.sun_angular_radius, a.sun_angular_radius)) add("sun_angular_radius");
    if (!Close(f.mu_s_min, a.mu_s_min)) add("mu_s_min");
    if (!differ.empty()) {
        Fail("neural weights ", source, " were fitted to another atmosphere (", differ, " differ)",
             fix);
    }
}

NeuralEvaluator MakeNeuralEvaluator(const NeuralWeights& w, const AtmosphereParameters& a) {
    NeuralEvaluator e;
    e.bottom = a.bottom_radius;
    e.top = a.top_radius;
    e.mie_g = a.mie_phase_g;
    e.ground_albedo = a.ground_albedo;
    e.encoding = w.encoding;
    e.transmittance = w.transmittance;
    e.scattering = w.scattering;
    return e;
}

ModelInfo NeuralModel::StaticInfo() {
    ModelInfo info;
    info.name = "neural";
    info.title = "Neural-network sky (thesis fitted model)";
    info.citation =
        "Leenman's 2025 thesis sections 9.6, 11.2.8, 11.3.2; Bruneton & Neyret 2008 (segments)";
    info.summary =
        "MLPs for transmittance (2-4-3) and scattering (4-8-8-3), fitted with `atmos fit`";
    info.capabilities.multiple_scattering = true;
    info.capabilities.precomputed = true;
    info.options = OptionRows().Specs();
    info.capabilities.spectral = false;  // its inputs are fitted weights, not coefficients
    info.capabilities.trainable = true;
    info.thesis_name = "Neural network";
    info.thesis_lines = 94;
    return info;
}

const OptionTable<NeuralOptions>& NeuralModel::OptionRows() {
    static const auto table =
        OptionTable<NeuralOptions>()
            .Choice("network", &NeuralOptions::network,
                    {{"thesis", std::string("thesis")}, {"large", std::string("large")}},
                    "shipped weights: thesis (4-8-8-3) or large (8-32-32-3, horizon inputs)")
            .Text("weights", &NeuralOptions::weights,
                  "weights JSON written by `atmos fit` (default: the shipped ones for earth)");
    return table;
}

NeuralModel::NeuralModel(const NeuralOptions& options) {
    weights_path_ = options.weights;
    network_ = options.network;
}

void NeuralModel::Prepare(const AtmosphereParameters& atmosphere) {
    CheckNeuralSingleMieLobe(atmosphere);
    SetAtmosphere(atmosphere);
    NeuralWeights w;
    std::string source;
    if (!weights_path_.empty()) {
        w = LoadNeuralWeights(weights_path_);
        source = "'" + weights_path_ + "'";
    } else {
        const std::string name = network_ == "large" ? "earth_large" : "earth";
        w = EmbeddedNeuralWeights(name);
        source = "data/neural/" + name + ".json";
    }
    CheckNeuralWeightsMatch(w, atmosphere, source);
    evaluator_ = MakeNeuralEvaluator(w, atmosphere);
}

}  // namespace atmos
