// atmos CLI: `atmos validate kider-2013`: spectral models against the measured
// clear sky of Kider et al. 2014 (harness/kider.h), errors as CSV.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "harness/html.h"
#include "harness/kider.h"
#include "harness/spectral_run.h"
#include "io/output_path.h"
#include "render/progressive.h"
#include "validate_fit.h"

namespace atmos::cli {

namespace {

struct ValidateOptions {
    std::string dataset;
    std::string data = "../shared/data/kider-2013";
    std::string models = "naive,bruneton";
    std::string atmosphere = "kider-2013";
    std::vector<std::string> sets;
    std::string captures;  // comma-separated "09:30,11:45"; empty: all
    std::string output;
    std::string html;
    std::string values;  // per-direction model values (CSV)
    bool theory_azimuth = false;
    int threads = 0;
    bool quiet = false;
    int64_t spp = 256;
    int64_t seed = 0;
    bool fit = false;
    // The path tracer (--spp paths, fixed seed): 8x faster than hillaire on this
    // job and inside its validity (hillaire's f_ms exceeds 0.5 here). Nine bins
    // spread over 372-795 nm, off the O2 / H2O bands and the strongest solar lines.
    std::string fit_model = "reference";
    std::string fit_wavelengths = "371.75,418.75,465.75,512.75,559.75,606.75,653.75,700.75,794.75";
    std::string fit_captures;  // empty: those of --captures
    int fit_evaluations = 40;
    bool fit_second_lobe = false;
};

std::vector<std::string> SplitList(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (!item.empty()) items.push_back(item);
    }
    return items;
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

// Bands of the 40 bins (nm, lower bound included). "360-720nm" is the range of
// clear-sky-models' RMSE (Bruneton 2017: its 31 samples 360-712.5 nm; docs/harness.md).
struct Band {
    const char* name;
    double lo, hi;
};
constexpr Band kBands[] = {{"360-500nm", 360, 500}, {"500-600nm", 500, 600},
                           {"600-700nm", 600, 700}, {"700-820nm", 700, 820},
                           {"360-720nm", 360, 720}, {"all", 0, 1e9}};

// One SVG per capture: the measured radiance at the bins nearest 440, 550 and 680
// nm (solid) and each model's (dashed) along the samples (rings from the horizon
// up, azimuths in file order; sample 0 excluded).
void WriteValidateHtml(const std::string& path, const std::vector<KiderSample>& samples,
                       const std::vector<std::string>& models,
                       const std::vector<std::vector<double>>& values, const std::string& title) {
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
    for (size_t m = 0; m < models.size(); ++m) {
        html << (m ? ", " : "") << HtmlEscape(models[m]) << ": dash " << (m + 1) * 2;
    }
    html << ").</p>\n";
    std::vector<std::string> captures;
    for (const KiderSample& s : samples) {
        if (std::find(captures.begin(), captures.end(), s.capture) == captures.end()) {
            captures.push_back(s.capture);
        }
    }
    for (const std::string& capture : captures) {
        std::vector<size_t> index;
        double top = 0.0;
        for (size_t q = 0; q < samples.size(); ++q) {
            if (samples[q].capture != capture) continue;
            index.push_back(q);
            for (int b : bins) top = std::max(top, samples[q].spectrum[b]);
        }
        for (size_t m = 0; m < models.size(); ++m) {
            for (size_t q : index) {
                for (int b : bins) {
                    top = std::max(top, values[m][q * kKiderBins + static_cast<size_t>(b)]);
                }
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
            for (size_t m = 0; m < models.size(); ++m) {
                line(
                    [&](size_t q) {
                        return values[m][q * kKiderBins + static_cast<size_t>(bins[c])];
                    },
                    colours[c], static_cast<int>(m + 1) * 2);
            }
        }
        html << "</svg>\n";
    }
    WriteFileAtomically(path, html.str());
}

int CmdValidate(const ValidateOptions& o) {
    if (o.dataset != "kider-2013") {
        Fail("validate: unknown data set '", o.dataset, "' (data sets: kider-2013)");
    }
    if (!o.output.empty()) CheckOutputFile(o.output);
    if (!o.html.empty()) CheckOutputFile(o.html);
    if (!o.values.empty()) CheckOutputFile(o.values);
    ThreadLimit limit(o.threads);
    const std::vector<KiderSample> all =
        ReadKiderCsv((std::filesystem::path(o.data) / "kider_ref.csv").string());
    const std::vector<std::string> wanted = SplitList(o.captures);
    std::vector<KiderSample> samples;
    for (const KiderSample& s : all) {
        if (s.suspect) continue;  // sample 0: the data's README
        if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), s.capture) == wanted.end()) {
            continue;
        }
        samples.push_back(s);
    }
    if (samples.empty()) Fail("validate: no capture matches --captures '", o.captures, "'");
    std::vector<SampleQuery> queries;
    for (const KiderSample& s : samples) queries.push_back(KiderQuery(s, o.theory_azimuth));
    const std::vector<double> nm = KiderWavelengths();
    std::vector<std::string> sets = o.sets;
    if (o.fit) {
        // The aerosol fitted on --fit-captures at --fit-wavelengths with --fit-model,
        // then every --model evaluated with it below (validate_fit.h).
        AerosolFitSettings settings;
        settings.model = o.fit_model;
        RequireSpectralModel(GetModelInfo(ParseModelSpec(o.fit_model).name));
        settings.monte_carlo = MakeMonteCarloSettings(o.spp, o.seed, 0, "--spp");
        settings.nm = ParseWavelengths(o.fit_wavelengths);
        settings.max_evaluations = o.fit_evaluations;
        settings.second_lobe = o.fit_second_lobe;
        settings.quiet = o.quiet;
        const std::vector<std::string> fit_wanted =
            o.fit_captures.empty() ? wanted : SplitList(o.fit_captures);
        std::vector<KiderSample> fit_samples;
        std::vector<SampleQuery> fit_queries;
        for (const KiderSample& s : all) {
            if (s.suspect) continue;
            if (!fit_wanted.empty() &&
                std::find(fit_wanted.begin(), fit_wanted.end(), s.capture) == fit_wanted.end()) {
                continue;
            }
            fit_samples.push_back(s);
            fit_queries.push_back(KiderQuery(s, o.theory_azimuth));
        }
        if (fit_samples.empty()) Fail("validate: no capture matches --fit-captures");
        const auto start = std::chrono::steady_clock::now();
        const AerosolFit fit = FitAerosol(settings, o.atmosphere, o.sets, fit_samples, fit_queries);
        sets = fit.sets;
        // The result (always printed: it is what --fit is for).
        std::fprintf(stderr,
                     "aerosol fit (%s, %zu directions x %zu wavelengths, %d evaluations, %.0f s, "
                     "%s): relative RMSE %.2f %% (start %.2f %%)\n",
                     o.fit_model.c_str(), fit_samples.size(), settings.nm.size(), fit.evaluations,
                     Seconds(start), fit.stop.c_str(), 100.0 * fit.residual,
                     100.0 * fit.start_residual);
        for (int i = 0; i < fit.count; ++i) {
            std::fprintf(stderr, "  %-7s %.6g (start %.6g, bounds [%g, %g])\n",
                         kAerosolParameters[i].name, fit.values[i], fit.start_values[i],
                         kAerosolParameters[i].lower, kAerosolParameters[i].upper);
        }
        std::string flags;
        for (size_t i = o.sets.size(); i < fit.sets.size(); ++i) flags += " --set " + fit.sets[i];
        std::fprintf(stderr, "  as flags:%s\n", flags.c_str());
    }
    const SpectralAtmosphere atmosphere = LoadSpectralAtmosphere(o.atmosphere, sets);

    std::ostringstream csv;
    csv << "model,capture,scope,region,rel_rmse_percent,abs_rmse_1e-3,mean_model_1e-3,"
           "mean_measured_1e-3,values\n";
    auto row = [&](const std::string& model, const std::string& capture, const std::string& scope,
                   const std::string& region, const ErrorSum& e, double model_sum) {
        char line[512];
        std::snprintf(line, sizeof(line), "%s,%s,%s,%s,%.3f,%.4f,%.4f,%.4f,%ld\n", model.c_str(),
                      capture.c_str(), scope.c_str(), region.c_str(), 100.0 * e.RelativeRmse(),
                      1e3 * e.AbsoluteRmse(), 1e3 * model_sum / std::max(1L, e.count),
                      1e3 * e.measured / std::max(1L, e.count), e.count);
        csv << line;
    };
    std::vector<std::string> model_texts = SplitList(o.models);
    std::vector<std::vector<double>> all_values;
    std::ostringstream values_csv;
    values_csv << "model,capture,sample";
    for (double l : nm) values_csv << ",L_" << WavelengthLabel(l);
    values_csv << "\n";
    for (const std::string& model_text : model_texts) {
        const ModelSpec spec = ParseModelSpec(model_text);
        const MonteCarloSettings mc = MakeMonteCarloSettings(o.spp, o.seed, 0, "--spp");
        const auto start = std::chrono::steady_clock::now();
        const std::vector<bool> answered = ModelBins(spec, atmosphere, nm);
        std::vector<double> model_nm;
        for (size_t i = 0; i < nm.size(); ++i) {
            if (answered[i]) model_nm.push_back(nm[i]);
        }
        if (model_nm.empty()) Fail("validate: model ", model_text, " answers none of the bins");
        const std::vector<double> answers =
            KiderModelSpectra(spec, atmosphere, model_nm, queries, mc);
        std::vector<double> values(queries.size() * nm.size(), std::nan(""));
        for (size_t q = 0, k = 0; q < queries.size(); ++q) {
            for (size_t i = 0; i < nm.size(); ++i) {
                if (answered[i]) values[q * nm.size() + i] = answers[k++];
            }
        }
        const double seconds = Seconds(start);
        if (!o.html.empty()) all_values.push_back(values);
        if (!o.values.empty()) {
            for (size_t q = 0; q < samples.size(); ++q) {
                values_csv << model_text << "," << samples[q].capture << "," << samples[q].sample;
                for (size_t i = 0; i < nm.size(); ++i) {
                    char v[32];
                    std::snprintf(v, sizeof v, ",%.6e", values[q * nm.size() + i]);
                    values_csv << v;
                }
                values_csv << "\n";
            }
        }
        // Sums per (capture, scope, region); capture "all" pools the captures.
        std::map<std::string, std::pair<ErrorSum, double>> sums;
        std::vector<std::string> order;
        auto add = [&](const std::string& key, double m, double d) {
            auto it = sums.find(key);
            if (it == sums.end()) {
                order.push_back(key);
                it = sums.emplace(key, std::make_pair(ErrorSum(), 0.0)).first;
            }
            it->second.first.Add(m, d);
            it->second.second += m;
        };
        std::map<std::string, std::pair<ErrorSum, double>> per_bin;
        for (size_t q = 0; q < samples.size(); ++q) {
            const KiderSample& s = samples[q];
            for (int i = 0; i < kKiderBins; ++i) {
                const double m = values[q * nm.size() + static_cast<size_t>(i)];
                if (std::isnan(m)) continue;  // a bin the model does not answer
                const double d = s.spectrum[i];
                for (const Band& band : kBands) {
                    if (nm[static_cast<size_t>(i)] < band.lo ||
                        nm[static_cast<size_t>(i)] >= band.hi) {
                        continue;
                    }
                    for (const std::string& capture : {s.capture, std::string("all")}) {
                        add(capture + "|" + band.name + "|all", m, d);
                        add(capture + "|" + band.name + "|" + KiderRegion(s), m, d);
                    }
                }
                auto& bin = per_bin[WavelengthLabel(nm[static_cast<size_t>(i)])];
                bin.first.Add(m, d);
                bin.second += m;
            }
        }
        std::sort(order.begin(), order.end(), [](const std::string& a, const std::string& b) {
            const bool a_all = a.rfind("all|", 0) == 0, b_all = b.rfind("all|", 0) == 0;
            return a_all != b_all ? b_all : a < b;
        });
        for (const std::string& key : order) {
            const size_t p1 = key.find('|'), p2 = key.find('|', p1 + 1);
            const auto& [e, model_sum] = sums[key];
            row(model_text, key.substr(0, p1), key.substr(p1 + 1, p2 - p1 - 1), key.substr(p2 + 1),
                e, model_sum);
        }
        // One row per bin, all captures pooled (scope "<nm>nm").
        for (double l : nm) {
            const std::string label = WavelengthLabel(l);
            if (per_bin.count(label) == 0) continue;  // not answered
            const auto& [e, model_sum] = per_bin[label];
            row(model_text, "all", label + "nm", "all", e, model_sum);
        }
        const ErrorSum& total = sums["all|all|all"].first;
        if (!o.quiet) {
            std::fprintf(stderr,
                         "%s: relative RMSE %.2f %%, absolute %.3f e-3 W m^-2 sr^-1 nm^-1 over %zu "
                         "directions x %zu bins (%.1f s)\n",
                         model_text.c_str(), 100.0 * total.RelativeRmse(),
                         1e3 * total.AbsoluteRmse(), samples.size(), model_nm.size(), seconds);
            const ErrorSum& csm = sums["all|360-720nm|all"].first;
            std::fprintf(stderr,
                         "  360-720nm (clear-sky-models' range) absolute RMSE %.3f e-3, relative "
                         "%.2f %%\n",
                         1e3 * csm.AbsoluteRmse(), 100.0 * csm.RelativeRmse());
            for (const char* region : {"near-sun", "aureole", "zenith", "horizon", "sky"}) {
                const auto it = sums.find(std::string("all|all|") + region);
                if (it == sums.end()) continue;
                const ErrorSum& e = it->second.first;
                std::fprintf(stderr, "  %-8s relative RMSE %6.2f %%, model/measured %.3f\n", region,
                             100.0 * e.RelativeRmse(), it->second.second / e.measured);
            }
        }
    }
    if (!o.html.empty()) {
        WriteValidateHtml(o.html, samples, model_texts, all_values,
                          "atmosphere " + o.atmosphere + ", data " + o.data);
    }
    if (!o.values.empty()) WriteFileAtomically(o.values, values_csv.str());
    if (o.output.empty()) {
        std::fputs(csv.str().c_str(), stdout);
    } else {
        WriteFileAtomically(o.output, csv.str());
    }
    return 0;
}

}  // namespace

Command AddValidateCommand(CLI::App* root) {
    auto o = std::make_shared<ValidateOptions>();
    Command c;
    c.app = root->add_subcommand(
        "validate",
        "spectral models against a measured sky (kider-2013: Kider et al. 2014's 15 clear-sky "
        "captures, 40 bins 360-818.25 nm); errors as CSV");
    c.app->add_option("dataset", o->dataset, "the measured data set: kider-2013")->required();
    c.app->add_option("--data", o->data, "directory holding kider_ref.csv")->capture_default_str();
    c.app->add_option("--models", o->models, "models, comma-separated (NAME[:OPT=V])")
        ->capture_default_str();
    c.app->add_option("--atmosphere,-a", o->atmosphere, "preset name or JSON file")
        ->capture_default_str();
    c.app->add_option("--set", o->sets, "override one atmosphere field: FIELD=VALUE");
    c.app->add_option("--captures", o->captures,
                      "captures to use, comma-separated (e.g. 09:30,11:45); default all 15");
    c.app->add_flag("--theory-azimuth", o->theory_azimuth,
                    "use the computed sun azimuth instead of the one estimated from the sky");
    c.app->add_option("--spp", o->spp, "Monte Carlo models: paths per direction")
        ->capture_default_str();
    c.app->add_option("--seed", o->seed, "Monte Carlo models: seed")->capture_default_str();
    c.app->add_option("-o,--output", o->output, "CSV file (default: stdout)");
    c.app->add_option("--values", o->values,
                      "CSV file of the model radiance per direction: model, capture, sample, "
                      "then L_<nm> per bin (W m^-2 sr^-1 nm^-1)");
    c.app->add_option("--html", o->html,
                      "HTML page with one plot per capture: measured and modelled radiance at "
                      "442, 548 and 677 nm along the samples");
    c.app->add_flag("--fit", o->fit,
                    "first fit the aerosol (Angstrom beta and alpha, single-scattering albedo, "
                    "Cornette-Shanks g; bounded least squares, NLopt BOBYQA) with --fit-model at "
                    "--fit-wavelengths on --fit-captures, then evaluate --models with it");
    c.app->add_option("--fit-model", o->fit_model, "--fit: the model evaluated by the fit")
        ->capture_default_str();
    c.app
        ->add_option("--fit-wavelengths", o->fit_wavelengths,
                     "--fit: Kider bins (nm) the fit compares, a list or START:STOP:COUNT")
        ->capture_default_str();
    c.app->add_option("--fit-captures", o->fit_captures,
                      "--fit: captures the fit compares (default: those of --captures)");
    c.app
        ->add_option("--fit-evaluations", o->fit_evaluations,
                     "--fit: the most model evaluations of the optimiser")
        ->capture_default_str();
    c.app->add_flag("--fit-second-lobe", o->fit_second_lobe,
                    "--fit: also fit the second Cornette-Shanks lobe (mie_phase_g2 in [0.5, 0.98], "
                    "mie_phase_weight2 in [0, 0.5])");
    c.app->add_option("--threads", o->threads, "worker threads (0: all cores)");
    c.app->add_flag("--quiet,-q", o->quiet, "no summary on stderr");
    c.run = [o] { return CmdValidate(*o); };
    return c;
}

}  // namespace atmos::cli
