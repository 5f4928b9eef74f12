// atmos: the models' declared validity domains (atmos/model.h ValidityDomain).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "atmos/model.h"
#include "physics/density.h"

namespace atmos {

namespace {

std::string Number(double value) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", value);
    return buf;
}

bool Differs(double a, double b, double rel) {
    return std::abs(a - b) > rel * std::max({std::abs(a), std::abs(b), 1e-300});
}

void CompareProfile(const char* name, const DensityProfile& a, const DensityProfile& b, double rel,
                    std::vector<std::string>* out) {
    for (int i = 0; i < 2; ++i) {
        const DensityProfileLayer& x = a.layers[i];
        const DensityProfileLayer& y = b.layers[i];
        const struct {
            const char* field;
            double value, fit;
        } fields[] = {{"width", x.width, y.width},
                      {"exp_term", x.exp_term, y.exp_term},
                      {"exp_scale", x.exp_scale, y.exp_scale},
                      {"linear_term", x.linear_term, y.linear_term},
                      {"constant_term", x.constant_term, y.constant_term}};
        for (const auto& f : fields) {
            if (i == 1 && std::string(f.field) == "width") continue;  // ignored (atmosphere.h)
            if (Differs(f.value, f.fit, rel)) {
                out->push_back(std::string(name) + ".layers[" + std::to_string(i) + "]." + f.field +
                               " " + Number(f.value) + " (fit: " + Number(f.fit) + ")");
            }
        }
    }
}

}  // namespace

std::vector<std::string> AtmosphereShapeDifferences(const AtmosphereParameters& a,
                                                    const AtmosphereParameters& fit) {
    std::vector<std::string> out;
    if (Differs(a.bottom_radius, fit.bottom_radius, 0.02)) {
        out.push_back("bottom_radius " + Number(a.bottom_radius) +
                      " (fit: " + Number(fit.bottom_radius) + ")");
    }
    CompareProfile("rayleigh_density", a.rayleigh_density, fit.rayleigh_density, 0.1, &out);
    return out;
}

double VerticalOpticalDepth(const AtmosphereParameters& a) {
    const double thickness = a.top_radius - a.bottom_radius;
    if (!(thickness > 0.0)) return 0.0;
    // Altitude 0 and a geometric grid from 1 m to the top (as EffectiveTopRadius):
    // a few-km scale height is resolved under a 10^9 m shell.
    constexpr int kPoints = 4096;
    const double ratio = std::pow(std::max(thickness, 1.0), 1.0 / (kPoints - 1));
    auto extinction_at = [&](double h) { return Extinction(a, GetDensities(a, h)); };
    Vec3d column;
    double h_above = thickness;
    Vec3d e_above = extinction_at(h_above);
    for (int k = kPoints - 2; k >= -1; --k) {
        const double h = k >= 0 ? std::min(std::pow(ratio, k), thickness) : 0.0;
        const Vec3d e = extinction_at(h);
        column += (e + e_above) * (0.5 * (h_above - h));
        h_above = h;
        e_above = e;
    }
    return MaxComponent(column);
}

double ColumnEquivalentHeight(const AtmosphereParameters& a) {
    const double ground = MaxComponent(Extinction(a, GetDensities(a, 0.0)));
    const double thickness = a.top_radius - a.bottom_radius;
    return ground > 0.0 ? std::min(VerticalOpticalDepth(a) / ground, thickness) : thickness;
}

std::vector<std::string> ValidityDomainViolations(const ModelInfo& info,
                                                  const AtmosphereParameters& atmosphere) {
    const ValidityDomain& d = info.domain;
    std::vector<std::string> out;
    if (d.fitted_atmosphere) {
        const std::vector<std::string> diffs =
            AtmosphereShapeDifferences(atmosphere, *d.fitted_atmosphere);
        if (!diffs.empty()) {
            std::string text = "its sky is a fit to the atmosphere '" + d.fitted_to +
                               "' and does not follow this one's (";
            for (size_t i = 0; i < diffs.size() && i < 3; ++i) {
                text += (i ? ", " : "") + diffs[i];
            }
            if (diffs.size() > 3) text += ", and " + std::to_string(diffs.size() - 3) + " more";
            out.push_back(text + ")");
        }
    }
    if (d.max_radius_ratio <= 0.0 && d.max_shell_heights <= 0.0 && d.max_radius_heights <= 0.0 &&
        d.max_optical_depth <= 0.0) {
        return out;  // no limit declared: nothing to measure
    }
    const double bottom = atmosphere.bottom_radius, top = atmosphere.top_radius;
    const double height = ColumnEquivalentHeight(atmosphere);
    const struct {
        double value, max;
        const char* what;
        const std::string& reason;
    } checks[] = {
        {top / bottom, d.max_radius_ratio, "top/bottom radius ratio", d.radius_ratio_reason},
        {(top - bottom) / height, d.max_shell_heights, "shell thickness in column heights",
         d.shell_heights_reason},
        {bottom / height, d.max_radius_heights, "planet radius in column heights",
         d.radius_heights_reason},
        {VerticalOpticalDepth(atmosphere), d.max_optical_depth, "vertical optical depth",
         d.optical_depth_reason},
    };
    for (const auto& c : checks) {
        if (c.max > 0.0 && c.value > c.max) {
            out.push_back(std::string(c.what) + " " + Number(c.value) + " above " + Number(c.max) +
                          ": " + c.reason);
        }
    }
    return out;
}

void WarnOutsideValidityDomain(const ModelInfo& info, const AtmosphereParameters& atmosphere) {
    for (const std::string& reason : ValidityDomainViolations(info, atmosphere)) {
        std::fprintf(stderr, "atmos: warning: model %s: outside its valid domain: %s\n",
                     info.name.c_str(), reason.c_str());
    }
}

}  // namespace atmos
