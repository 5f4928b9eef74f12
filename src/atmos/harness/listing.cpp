// atmos: what `atmos list` prints about a model (harness/listing.h).
#include "harness/listing.h"

#include <cstdio>
#include <string>

namespace atmos {

namespace {

std::string Line(const std::string& text) {
    return "  " + std::string(16, ' ') + "   " + text + "\n";
}

std::string Number(double value) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", value);
    return buf;
}

}  // namespace

std::string ModelCapabilitiesText(const ModelInfo& info) {
    const ModelCapabilities& c = info.capabilities;
    std::string quantities = c.radiance ? "radiance" : "";
    if (c.radiance && c.transmittance) quantities += ", ";
    if (c.transmittance) quantities += "transmittance";
    std::string text =
        Line("quantities: " + quantities + "; space views: " + (c.space_views ? "yes" : "no") +
             "; sun below horizon: " + (c.sun_below_horizon ? "yes" : "no") +
             "; multiple scattering: " + (c.multiple_scattering ? "yes" : "no") +
             (c.precomputed ? "; precomputed" : "") + (c.stochastic ? "; Monte Carlo" : ""));
    for (const std::string& note : c.validity_notes) text += Line("validity: " + note);
    const ValidityDomain& d = info.domain;
    const struct {
        double max;
        const char* what;
        const char* unit;
        const std::string& reason;
    } limits[] = {
        {d.max_radius_ratio, "top/bottom radius ratio", "", d.radius_ratio_reason},
        {d.max_shell_heights, "shell thickness", " column heights", d.shell_heights_reason},
        {d.max_radius_heights, "planet radius", " column heights", d.radius_heights_reason},
        {d.max_optical_depth, "vertical optical depth", "", d.optical_depth_reason},
    };
    if (d.fitted_atmosphere) {
        text += Line("valid domain: the atmosphere its sky is fitted to, '" + d.fitted_to +
                     "' (its planet radius and air profile); on another planet it warns and gives "
                     "that sky anyway");
    }
    for (const auto& l : limits) {
        if (l.max <= 0.0) continue;
        text += Line(std::string("valid domain: ") + l.what + " up to " + Number(l.max) + l.unit +
                     ": " + l.reason);
    }
    return text;
}

std::string ModelOptionFlagHint(const std::vector<std::string>& args) {
    std::string given_model;
    for (size_t i = 0; i + 1 < args.size(); ++i) {
        if (args[i] == "--model" || args[i] == "-m") given_model = args[i + 1];
    }
    given_model = given_model.substr(0, given_model.find(':'));
    for (const std::string& arg : args) {
        if (arg.rfind("--", 0) != 0) continue;
        for (const ModelInfo& info : ListModels()) {
            if (!given_model.empty() && info.name != given_model) continue;
            for (const ModelOptionSpec& spec : info.options) {
                if (arg.substr(2) == spec.name) {
                    return " (model options are part of the model: --model " + info.name + ":" +
                           spec.name + "=VALUE; `atmos list " + info.name + "` prints them)";
                }
            }
        }
    }
    return "";
}

}  // namespace atmos
