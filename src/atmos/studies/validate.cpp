// atmos studies: the validate study (validate.h).
#include "studies/validate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <tuple>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "harness/html.h"
#include "harness/spectral_run.h"
#include "render/progressive.h"

namespace atmos {

namespace {

// Bands of the 40 bins (nm, lower bound included). "360-720nm" is the range of
// clear-sky-models' RMSE (Bruneton 2017: its 31 samples 360-712.5 nm; docs/harness.md).
struct Band {
    const char* name;
    double lo, hi;
};
constexpr Band kBands[] = {{"360-500nm", 360, 500}, {"500-600nm", 500, 600},
                           {"600-700nm", 600, 700}, {"700-820nm", 700, 820},
                           {"360-720nm", 360, 720}, {"all", 0, 1e9}};

std::string Join(const std::vector<std::string>& items) {
    std::string s;
    for (size_t i = 0; i < items.size(); ++i) s += (i ? "," : "") + items[i];
    return s;
}

// The non-suspect samples (sample 0: the data's README) of the wanted captures.
std::vector<KiderSample> Select(const std::vector<KiderSample>& all,
                                const std::vector<std::string>& wanted) {
    std::vector<KiderSample> samples;
    for (const KiderSample& s : all) {
        if (s.suspect) continue;
        if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), s.capture) == wanted.end()) {
            continue;
        }
        samples.push_back(s);
    }
    return samples;
}

// The bins a model answers: a model whose spectral form covers only part of
// the range (hosek-wilkie: 320-720 nm) refuses the others in SetSpectralBatch;
// its errors are then over the bins it answers (the rest are NaN, skipped).
std::vector<bool> ModelBins(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                            const std::vector<double>& nm) {
    std::vector<bool> ok(nm.size(), true);
    const std::unique_ptr<Model> model = CreateModel(spec.name, spec.options);
    for (size_t i = 0; i < nm.size(); ++i) {
        const double three[3] = {nm[i], nm[i], nm[i]};
        try {
            model->SetSpectralBatch(atmosphere, three);
        } catch (const Error&) {
            ok[i] = false;
        }
    }
    return ok;
}

double Seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The error rows of one model: per (capture, band, region), capture "all"
// pooling the captures, sorted with the pooled rows last; then one row per bin.
std::vector<ValidateErrorRow> ErrorRows(const std::vector<KiderSample>& samples,
                                        const std::vector<double>& nm,
                                        const std::vector<double>& values) {
    using Key = std::tuple<std::string, std::string, std::string>;
    std::map<Key, ValidateErrorRow> sums;
    auto add = [&](const std::string& capture, const std::string& scope, const std::string& region,
                   double m, double d) {
        ValidateErrorRow& r = sums[Key{capture, scope, region}];
        r.capture = capture;
        r.scope = scope;
        r.region = region;
        r.error.Add(m, d);
        r.model_sum += m;
    };
    std::map<std::string, ValidateErrorRow> per_bin;
    for (size_t q = 0; q < samples.size(); ++q) {
        const KiderSample& s = samples[q];
        for (int i = 0; i < kKiderBins; ++i) {
            const double l = nm[static_cast<size_t>(i)];
            const double m = values[q * nm.size() + static_cast<size_t>(i)];
            if (std::isnan(m)) continue;  // a bin the model does not answer
            const double d = s.spectrum[i];
            for (const Band& band : kBands) {
                if (l < band.lo || l >= band.hi) continue;
                for (const std::string& capture : {s.capture, std::string("all")}) {
                    add(capture, band.name, "all", m, d);
                    add(capture, band.name, KiderRegion(s), m, d);
                }
            }
            ValidateErrorRow& bin = per_bin[WavelengthLabel(l)];
            bin.error.Add(m, d);
            bin.model_sum += m;
        }
    }
    std::vector<ValidateErrorRow> rows;
    for (auto& [key, row] : sums) rows.push_back(row);
    // The table's order: the captures' rows by "capture|scope|region", the pooled last.
    const auto joined = [](const ValidateErrorRow& r) {
        return r.capture + "|" + r.scope + "|" + r.region;
    };
    std::sort(rows.begin(), rows.end(), [&](const ValidateErrorRow& a, const ValidateErrorRow& b) {
        const bool a_all = a.capture == "all", b_all = b.capture == "all";
        return a_all != b_all ? b_all : joined(a) < joined(b);
    });
    for (double l : nm) {
        if (per_bin.count(WavelengthLabel(l)) == 0) continue;  // not answered
        ValidateErrorRow row = per_bin[WavelengthLabel(l)];
        row.capture = "all";
        row.scope = WavelengthLabel(l) + "nm";
        row.region = "all";
        rows.push_back(row);
    }
    return rows;
}

}  // namespace

const ValidateErrorRow* ValidateModelResult::Find(const std::string& capture,
                                                  const std::string& scope,
                                                  const std::string& region) const {
    for (const ValidateErrorRow& r : rows) {
        if (r.capture == capture && r.scope == scope && r.region == region) return &r;
    }
    return nullptr;
}

ValidateConfig ResolveValidateConfig(ValidateConfig config) {
    if (config.dataset != "kider-2013") {
        Fail("validate: unknown data set '", config.dataset, "' (data sets: kider-2013)");
    }
    for (const std::string& m : config.models) ParseModelSpec(m);  // fail early
    if (config.fit) {
        RequireSpectralModel(GetModelInfo(ParseModelSpec(config.fit_model).name));
        MakeMonteCarloSettings(config.spp, config.seed, 0, "--spp");
    }
    return config;
}

std::vector<KiderSample> ReadValidateData(const ValidateConfig& config) {
    return ReadKiderCsv((std::filesystem::path(config.data_dir) / "kider_ref.csv").string());
}

ValidateResult RunValidate(const ValidateConfig& config, const std::vector<KiderSample>& all,
                           const std::function<void(const ValidateResult&)>& progress) {
    ValidateResult result;
    result.samples = Select(all, config.captures);
    if (result.samples.empty()) {
        Fail("validate: no capture matches --captures '", Join(config.captures), "'");
    }
    std::vector<SampleQuery> queries;
    for (const KiderSample& s : result.samples) {
        queries.push_back(KiderQuery(s, config.theory_azimuth));
    }
    result.nm = KiderWavelengths();
    result.sets = config.sets;
    const MonteCarloSettings mc = MakeMonteCarloSettings(config.spp, config.seed, 0, "--spp");
    if (config.fit) {
        // The aerosol fitted on the fit's captures and bins with its model, then
        // every model evaluated with it below (aerosol_fit.h).
        AerosolFitSettings settings;
        settings.model = config.fit_model;
        RequireSpectralModel(GetModelInfo(ParseModelSpec(config.fit_model).name));
        settings.monte_carlo = mc;
        settings.nm = config.fit_nm;
        settings.max_evaluations = config.fit_evaluations;
        settings.second_lobe = config.fit_second_lobe;
        settings.quiet = config.quiet;
        const std::vector<KiderSample> fit_samples =
            Select(all, config.fit_captures.empty() ? config.captures : config.fit_captures);
        if (fit_samples.empty()) Fail("validate: no capture matches --fit-captures");
        std::vector<SampleQuery> fit_queries;
        for (const KiderSample& s : fit_samples) {
            fit_queries.push_back(KiderQuery(s, config.theory_azimuth));
        }
        const auto start = std::chrono::steady_clock::now();
        result.fit = FitAerosol(settings, config.atmosphere, config.sets, fit_samples, fit_queries);
        result.fit_seconds = Seconds(start);
        result.fit_samples = fit_samples.size();
        result.fitted = true;
        result.sets = result.fit.sets;
        if (progress) progress(result);
    }
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(config.atmosphere, result.sets);
    for (const std::string& model : config.models) {
        ValidateModelResult m;
        m.model = model;
        const auto start = std::chrono::steady_clock::now();
        const ModelSpec spec = ParseModelSpec(model);
        const std::vector<bool> answered = ModelBins(spec, atmosphere, result.nm);
        std::vector<double> model_nm;
        for (size_t i = 0; i < result.nm.size(); ++i) {
            if (answered[i]) model_nm.push_back(result.nm[i]);
        }
        if (model_nm.empty()) Fail("validate: model ", model, " answers none of the bins");
        m.bins_answered = model_nm.size();
        const std::vector<double> answers =
            KiderModelSpectra(spec, atmosphere, model_nm, queries, mc);
        m.values.assign(queries.size() * result.nm.size(), std::nan(""));
        for (size_t q = 0, k = 0; q < queries.size(); ++q) {
            for (size_t i = 0; i < result.nm.size(); ++i) {
                if (answered[i]) m.values[q * result.nm.size() + i] = answers[k++];
            }
        }
        m.seconds = Seconds(start);
        m.rows = ErrorRows(result.samples, result.nm, m.values);
        result.models.push_back(std::move(m));
        if (progress) progress(result);
    }
    return result;
}

std::string ValidateErrorsCsv(const ValidateResult& result) {
    std::string csv =
        "model,capture,scope,region,rel_rmse_percent,abs_rmse_1e-3,mean_model_1e-3,"
        "mean_measured_1e-3,values\n";
    for (const ValidateModelResult& m : result.models) {
        for (const ValidateErrorRow& r : m.rows) {
            const ErrorSum& e = r.error;
            char line[512];
            std::snprintf(line, sizeof(line), "%s,%s,%s,%s,%.3f,%.4f,%.4f,%.4f,%ld\n",
                          m.model.c_str(), r.capture.c_str(), r.scope.c_str(), r.region.c_str(),
                          100.0 * e.RelativeRmse(), 1e3 * e.AbsoluteRmse(),
                          1e3 * r.model_sum / std::max(1L, e.count),
                          1e3 * e.measured / std::max(1L, e.count), e.count);
            csv += line;
        }
    }
    return csv;
}

std::string ValidateValuesCsv(const ValidateResult& result) {
    std::ostringstream csv;
    csv << "model,capture,sample";
    for (double l : result.nm) csv << ",L_" << WavelengthLabel(l);
    csv << "\n";
    const size_t n = result.nm.size();
    for (const ValidateModelResult& m : result.models) {
        for (size_t q = 0; q < result.samples.size(); ++q) {
            csv << m.model << "," << result.samples[q].capture << "," << result.samples[q].sample;
            for (size_t i = 0; i < n; ++i) {
                char v[32];
                const double value = m.values[q * n + i];
                if (std::isnan(value)) {
                    std::snprintf(v, sizeof v, ",");  // a bin the model does not answer
                } else {
                    std::snprintf(v, sizeof v, ",%.6e", value);
                }
                csv << v;
            }
            csv << "\n";
        }
    }
    return csv.str();
}

// One SVG per capture: the measured radiance at the bins nearest 440, 550 and 680
// nm (solid) and each model's (dashed) along the samples (rings from the horizon
// up, azimuths in file order; sample 0 excluded).
std::string ValidateHtml(const ValidateResult& result, const std::string& title) {
    const std::vector<KiderSample>& samples = result.samples;
    const int bins[3] = {7, 16, 27};  // 442.25, 548, 677.25 nm
    const char* colours[3] = {"#2255cc", "#22aa44", "#cc3322"};
    std::ostringstream html;
    html << "<!doctype html><meta charset=\"utf-8\"><title>atmos validate</title>"
            "<style>body{font-family:sans-serif}svg{border:1px solid #ccc;margin:4px}</style>"
            "<h1>atmos validate kider-2013</h1><p>"
         << HtmlEscape(title)
         << "</p><p>Radiance (W m<sup>-2</sup> sr<sup>-1</sup> nm<sup>-1</sup>) at 442.25 "
            "(blue), 548 (green) and 677.25 nm (red) along the 80 samples of each capture "
            "(rings from the horizon, 12.1&deg;, to the zenith): measured solid, models "
            "dashed (";
    for (size_t m = 0; m < result.models.size(); ++m) {
        html << (m ? ", " : "") << HtmlEscape(result.models[m].model) << ": dash " << (m + 1) * 2;
    }
    html << ").</p>\n";
    std::vector<std::string> captures;
    for (const KiderSample& s : samples) {
        if (std::find(captures.begin(), captures.end(), s.capture) == captures.end()) {
            captures.push_back(s.capture);
        }
    }
    const auto model_value = [&](size_t m, size_t q, int b) {
        return result.models[m].values[q * kKiderBins + static_cast<size_t>(b)];
    };
    for (const std::string& capture : captures) {
        std::vector<size_t> index;
        double top = 0.0;
        for (size_t q = 0; q < samples.size(); ++q) {
            if (samples[q].capture != capture) continue;
            index.push_back(q);
            for (int b : bins) top = std::max(top, samples[q].spectrum[b]);
        }
        for (size_t m = 0; m < result.models.size(); ++m) {
            for (size_t q : index) {
                for (int b : bins) top = std::max(top, model_value(m, q, b));
            }
        }
        const double w = 480, h = 240;
        auto x = [&](size_t i) {
            return 30.0 + (w - 40.0) * i / std::max<size_t>(1, index.size() - 1);
        };
        auto y = [&](double v) { return h - 20.0 - (h - 30.0) * v / (top > 0 ? top : 1.0); };
        html << "<svg width=\"" << w << "\" height=\"" << h << "\"><text x=\"35\" y=\"14\">"
             << HtmlEscape(capture) << ", max " << top << "</text>";
        auto line = [&](const std::function<double(size_t)>& value, const char* colour, int dash) {
            html << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.2\"";
            if (dash) html << " stroke-dasharray=\"" << dash << "," << dash << "\"";
            html << " points=\"";
            for (size_t i = 0; i < index.size(); ++i)
                html << x(i) << "," << y(value(index[i])) << " ";
            html << "\"/>";
        };
        for (int c = 0; c < 3; ++c) {
            line([&](size_t q) { return samples[q].spectrum[bins[c]]; }, colours[c], 0);
            for (size_t m = 0; m < result.models.size(); ++m) {
                line([&](size_t q) { return model_value(m, q, bins[c]); }, colours[c],
                     static_cast<int>(m + 1) * 2);
            }
        }
        html << "</svg>\n";
    }
    return html.str();
}

std::string AerosolFitSummary(const ValidateResult& result, const ValidateConfig& config) {
    if (!result.fitted) return "";
    const AerosolFit& fit = result.fit;
    std::string text;
    char line[512];
    std::snprintf(line, sizeof line,
                  "aerosol fit (%s, %zu directions x %zu wavelengths, %d evaluations, %.0f s, "
                  "%s): relative RMSE %.2f %% (start %.2f %%)\n",
                  config.fit_model.c_str(), result.fit_samples, config.fit_nm.size(),
                  fit.evaluations, result.fit_seconds, fit.stop.c_str(), 100.0 * fit.residual,
                  100.0 * fit.start_residual);
    text += line;
    for (int i = 0; i < fit.count; ++i) {
        std::snprintf(line, sizeof line, "  %-7s %.6g (start %.6g, bounds [%g, %g])\n",
                      kAerosolParameters[i].name, fit.values[i], fit.start_values[i],
                      kAerosolParameters[i].lower, kAerosolParameters[i].upper);
        text += line;
    }
    std::string flags;
    for (size_t i = config.sets.size(); i < fit.sets.size(); ++i) flags += " --set " + fit.sets[i];
    return text + "  as flags:" + flags + "\n";
}

std::string ValidateModelSummary(const ValidateModelResult& model, size_t directions) {
    std::string text;
    char line[512];
    const ValidateErrorRow* total = model.Find("all", "all", "all");
    const ValidateErrorRow* csm = model.Find("all", "360-720nm", "all");
    if (!total || !csm) return text;
    std::snprintf(line, sizeof line,
                  "%s: relative RMSE %.2f %%, absolute %.3f e-3 W m^-2 sr^-1 nm^-1 over %zu "
                  "directions x %zu bins (%.1f s)\n",
                  model.model.c_str(), 100.0 * total->error.RelativeRmse(),
                  1e3 * total->error.AbsoluteRmse(), directions, model.bins_answered,
                  model.seconds);
    text += line;
    std::snprintf(line, sizeof line,
                  "  360-720nm (clear-sky-models' range) absolute RMSE %.3f e-3, relative "
                  "%.2f %%\n",
                  1e3 * csm->error.AbsoluteRmse(), 100.0 * csm->error.RelativeRmse());
    text += line;
    for (const char* region : {"near-sun", "aureole", "zenith", "horizon", "sky"}) {
        const ValidateErrorRow* r = model.Find("all", "all", region);
        if (!r) continue;
        std::snprintf(line, sizeof line, "  %-8s relative RMSE %6.2f %%, model/measured %.3f\n",
                      region, 100.0 * r->error.RelativeRmse(), r->model_sum / r->error.measured);
        text += line;
    }
    return text;
}

}  // namespace atmos
