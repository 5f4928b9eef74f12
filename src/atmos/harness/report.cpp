// atmos: the HTML report of `atmos compare` (see report.h).
#include "harness/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "atmos/error.h"
#include "atmos/image.h"
#include "harness/html.h"
#include "harness/machine.h"
#include "harness/ranking.h"
#include "harness/regimes.h"
#include "harness/svg.h"
#include "io/output_path.h"
#include "metrics/flip.h"

namespace atmos {

namespace {

// printf-like "%.<digits>f" and "%.<digits>g" without a non-literal format string.
std::string Fixed(double v, int digits) {
    std::ostringstream os;
    os.setf(std::ios::fixed);
    os.precision(digits);
    os << v;
    return os.str();
}
std::string General(double v, int digits) {
    std::ostringstream os;
    os.precision(digits);
    os << v;
    return os.str();
}

// One metric table, best (lowest) per row highlighted, flagged cells marked.
void MetricTable(std::ostream& f, const std::string& title, int digits, const CompareResult& r,
                 bool flip) {
    f << "<table class=\"metric\"><caption>" << HtmlEscape(title)
      << "</caption>\n<tr><th>view</th>";
    for (size_t m = 0; m < r.models.size(); ++m) {
        f << "<th title=\"" << HtmlEscape(r.model_titles[m]) << "\">" << HtmlEscape(r.models[m])
          << "</th>";
    }
    const bool has_noise = flip && !r.rows.empty() && r.rows.front().reference_noise >= 0.0;
    if (has_noise) {
        f << "<th title=\"HDR-FLIP between the reference's two independent halves\">reference "
             "noise</th>";
    }
    f << "</tr>\n";
    for (const CompareRow& row : r.rows) {
        std::vector<double> values;
        for (const CompareCell& c : row.cells) values.push_back(flip ? c.flip : c.rmse);
        const double noise = flip ? row.reference_noise : row.reference_rmse_noise;
        const std::vector<int> best = BestOfRow(values, noise);
        const bool tie = best.size() > 1;
        f << "<tr><th>" << HtmlEscape(row.label) << "</th>";
        for (size_t m = 0; m < row.cells.size(); ++m) {
            const CompareCell& c = row.cells[m];
            const bool is_best =
                std::find(best.begin(), best.end(), static_cast<int>(m)) != best.end();
            const bool unresolved = flip && c.within_noise;
            std::string tip = c.validity_note;
            if (is_best) {
                tip += std::string(tip.empty() ? "" : "; ") +
                       (tie ? "tied best: within the reference's noise (" + General(noise, 3) +
                                  ") of the lowest value"
                        : noise > 0.0 ? "best: leads the next by more than the reference's "
                                        "noise (" +
                                            General(noise, 3) + ")"
                                      : "lowest");
            }
            if (unresolved) {
                tip += std::string(tip.empty() ? "" : "; ") +
                       "at or below the reference's own noise: not resolved";
            }
            f << "<td";
            if (is_best || unresolved) {
                f << " class=\"" << (is_best ? (tie ? "tie" : "best") : "")
                  << (is_best && unresolved ? " " : "") << (unresolved ? "noise" : "") << "\"";
            }
            if (!tip.empty()) f << " title=\"" << HtmlEscape(tip) << "\"";
            f << ">" << Fixed(values[m], digits) << (c.validity_note.empty() ? "" : " &dagger;")
              << (unresolved ? " &asymp;" : "") << (is_best && tie ? " =" : "") << "</td>";
        }
        if (has_noise) f << "<td class=\"noise\">" << Fixed(row.reference_noise, digits) << "</td>";
        f << "</tr>\n";
    }
    f << "</table>\n";
}

double MeanSeconds(const CompareResult& r, int m, bool* cached) {
    double sum = 0.0;
    *cached = false;
    for (const CompareRow& row : r.rows) {
        sum += m < 0 ? row.reference_seconds : row.cells[static_cast<size_t>(m)].render_seconds;
        *cached |= m < 0 ? row.reference_cached : row.cells[static_cast<size_t>(m)].cached;
    }
    return sum / static_cast<double>(std::max<size_t>(1, r.rows.size()));
}

// A model's Prepare() seconds when it precomputes (its capabilities say so;
// the others' Prepare() does next to nothing), else 0.
double PrecomputeSeconds(const CompareResult& r, size_t m) {
    if (m >= r.prepare_seconds.size()) return 0.0;
    try {
        return GetModelInfo(r.model_names[m]).capabilities.precomputed ? r.prepare_seconds[m] : 0.0;
    } catch (const Error&) {
        return 0.0;
    }
}

std::string Duration(double seconds) {
    if (seconds >= 1.0) return General(seconds, 3) + " s";
    return General(1000.0 * seconds, 3) + " ms";
}

std::string Bytes(int64_t bytes) {
    if (bytes < 0) return "&ndash;";
    if (bytes >= (int64_t{1} << 20))
        return Fixed(static_cast<double>(bytes) / (1 << 20), 1) + " MiB";
    return Fixed(static_cast<double>(bytes) / 1024.0, 1) + " KiB";
}

// Horizontal bars on a log axis: the mean render time per view of each model,
// precomputation as text; the reference's time is given apart (it is orders
// of magnitude slower and would set the scale).
void TimeChart(std::ostream& f, const CompareConfig& config, const CompareResult& r) {
    std::vector<double> seconds;
    std::vector<bool> cached;
    double lo = INFINITY, hi = 0.0;
    for (size_t m = 0; m < r.models.size(); ++m) {
        bool c = false;
        seconds.push_back(MeanSeconds(r, static_cast<int>(m), &c));
        cached.push_back(c);
        if (seconds.back() > 0.0) {
            lo = std::min(lo, seconds.back());
            hi = std::max(hi, seconds.back());
        }
    }
    if (!(hi > 0.0)) lo = hi = 1e-3;
    const int label_w = 230, bar_w = 460, row_h = 24, top = 10;
    const int height = row_h * static_cast<int>(r.models.size()) + top + 46;
    const SvgAxis x = MakeSvgAxis(lo, hi, true, label_w, label_w + bar_w);
    const SvgAxis y{0.0, 1.0, false, static_cast<double>(height - 46), static_cast<double>(top)};
    f << "<svg class=\"plot\" data-plot=\"times\" xmlns=\"http://www.w3.org/2000/svg\" width=\""
      << label_w + bar_w + 330 << "\" height=\"" << height
      << "\" role=\"img\" aria-label=\"render times of the models, log scale\">\n";
    SvgAxes(f, x, y,
            "mean render time per view (s, log scale), " + std::to_string(config.width) + "x" +
                std::to_string(config.height) + ", " + std::to_string(r.threads) + " threads",
            "", false);
    for (size_t m = 0; m < r.models.size(); ++m) {
        const int yy = top + static_cast<int>(m) * row_h + 3;
        const double w = std::max(1.0, x.Map(std::max(seconds[m], x.lo)) - x.px0);
        std::string text = Duration(seconds[m]);
        if (PrecomputeSeconds(r, m) > 0.0)
            text += " + prepare " + Duration(PrecomputeSeconds(r, m));
        if (cached[m]) text += " (cached: the time of the original render)";
        f << "<text x=\"" << label_w - 8 << "\" y=\"" << yy + 14
          << "\" text-anchor=\"end\" fill=\"#ddd\" font-size=\"12\">" << HtmlEscape(r.models[m])
          << "</text><rect x=\"" << label_w << "\" y=\"" << yy << "\" width=\"" << Fixed(w, 1)
          << "\" height=\"" << row_h - 7 << "\" fill=\"" << SeriesColour(m) << "\"><title>"
          << HtmlEscape(r.models[m] + ": " + text) << "</title></rect><text x=\""
          << Fixed(label_w + w + 6, 1) << "\" y=\"" << yy + 13
          << "\" fill=\"#bbb\" font-size=\"11\">" << HtmlEscape(text) << "</text>\n";
    }
    f << "</svg>\n";
    bool ref_cached = false;
    const double ref = MeanSeconds(r, -1, &ref_cached);
    f << "<p>Reference (" << HtmlEscape(config.reference_model)
      << "), apart from the chart: " << Duration(ref) << " per view"
      << (ref_cached ? " (cached: the original render's time)" : "");
    size_t shipped = 0;
    for (const CompareRow& row : r.rows) shipped += row.reference_source == "shipped" ? 1 : 0;
    if (shipped > 0) {
        f << " (" << shipped << " of " << r.rows.size()
          << " views shipped, not rendered: counted as 0 s)";
    }
    if (hi > 0.0 && ref > 0.0) f << ", " << General(ref / hi, 3) << "&times; the slowest model";
    f << ".</p>\n";
}

// The summary: one line per model, ranked by mean FLIP with ties within the
// mean reference noise.
void SummaryTable(std::ostream& f, const CompareConfig& config, const CompareResult& r,
                  const std::vector<CompareSummary>& summary) {
    std::vector<size_t> order(summary.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return summary[a].mean_flip < summary[b].mean_flip;
    });
    std::vector<int> count(summary.size() + 1, 0);
    for (const CompareSummary& s : summary) ++count[static_cast<size_t>(s.rank)];
    const std::string size = std::to_string(config.width) + "x" + std::to_string(config.height);
    f << "<table class=\"summary\"><caption>Ranked by mean FLIP over the " << r.rows.size()
      << " views (<a href=\"accuracy_cost.csv\">accuracy_cost.csv</a>)</caption>\n"
      << "<tr><th>rank</th><th>model</th><th title=\"mean over the views; the worst view in "
         "brackets\">mean FLIP (worst view)</th><th title=\"views where the model's FLIP is at "
         "or below the reference's noise\">unresolved views</th><th>per frame, "
      << size
      << "</th><th title=\"the report's time scaled by the pixel count (the per-pixel loop "
         "dominates; fixed costs are overestimated)\">per frame, 1920x1080 (extrapolated)</th>"
         "<th>precompute</th><th title=\"the precomputed tables as float32 (atmos bake's "
         "tables.f32)\">table memory</th><th>lines of code</th><th>Pareto front</th>"
         "<th>validity</th></tr>\n";
    for (size_t i : order) {
        const CompareSummary& s = summary[i];
        const bool tied = count[static_cast<size_t>(s.rank)] > 1;
        f << "<tr><td" << (s.rank == 1 ? (tied ? " class=\"tie\"" : " class=\"best\"") : "")
          << (tied ? " title=\"tied: within the mean reference noise of the group's first\"" : "")
          << ">" << s.rank << (tied ? " =" : "") << "</td><th title=\""
          << HtmlEscape(r.model_titles[i]) << "\">" << HtmlEscape(s.model) << "</th><td>"
          << Fixed(s.mean_flip, 4) << " (" << Fixed(s.worst_flip, 3) << " "
          << HtmlEscape(s.worst_view) << ")</td><td>" << s.unresolved_views << "</td><td>"
          << Duration(s.frame_seconds) << "</td><td>" << Duration(s.frame_seconds_1080p)
          << "</td><td>"
          << (s.prepare_seconds > 0.0 ? Duration(s.prepare_seconds) : std::string("&ndash;"))
          << "</td><td>" << Bytes(s.table_bytes) << "</td><td>"
          << (s.lines >= 0 ? std::to_string(s.lines) : std::string("&ndash;")) << "</td><td>"
          << (s.pareto                 ? "yes"
              : s.pareto_apart.empty() ? ""
                                       : "apart: " + s.pareto_apart)
          << "</td><td style=\"text-align:left;white-space:normal\">" << HtmlEscape(s.validity)
          << "</td></tr>\n";
    }
    f << "</table>\n";
}

// Mean FLIP (worst view as a whisker) against the render time per frame, log
// axes, with the precomputation as a hollow diamond and the Pareto front.
void AccuracyCostPlot(std::ostream& f, const CompareConfig& config, const CompareResult& r,
                      const std::vector<CompareSummary>& summary) {
    const double left = 70, right = 620, top = 20, bottom = 330;
    double tlo = INFINITY, thi = 0.0, elo = INFINITY, ehi = 0.0;
    for (const CompareSummary& s : summary) {
        for (double t : {s.frame_seconds, s.prepare_seconds}) {
            if (t > 0.0) {
                tlo = std::min(tlo, t);
                thi = std::max(thi, t);
            }
        }
        for (double e : {s.mean_flip, s.worst_flip}) {
            if (e > 0.0) {
                elo = std::min(elo, e);
                ehi = std::max(ehi, e);
            }
        }
    }
    const double noise = MeanReferenceNoise(r);
    if (noise > 0.0) {
        elo = std::min(elo, noise);
        ehi = std::max(ehi, noise);
    }
    if (!(thi > 0.0)) tlo = thi = 1e-3;
    if (!(ehi > 0.0)) elo = ehi = 1e-3;
    const SvgAxis x = MakeSvgAxis(tlo, thi, true, left, right);
    const SvgAxis y = MakeSvgAxis(elo, ehi, ehi / elo > 8.0, bottom, top);
    f << "<svg class=\"plot\" data-plot=\"accuracy-cost\" xmlns=\"http://www.w3.org/2000/svg\" "
         "width=\"900\" height=\""
      << bottom + 50 << "\" role=\"img\" aria-label=\"accuracy against cost\">\n";
    SvgAxes(f, x, y,
            "render time per frame at " + std::to_string(config.width) + "x" +
                std::to_string(config.height) + " (s, log); hollow: precompute time",
            std::string("mean ") + (config.quantity == Quantity::kTransmittance ? "LDR" : "HDR") +
                "-FLIP over the views" + (y.log ? " (log)" : ""));
    if (noise > 0.0) {
        const double py = y.Map(noise);
        f << "<line x1=\"" << left << "\" x2=\"" << right << "\" y1=\"" << Fixed(py, 1)
          << "\" y2=\"" << Fixed(py, 1)
          << "\" stroke=\"#888\" stroke-dasharray=\"2 3\"><title>mean reference noise "
          << General(noise, 3)
          << ": below it the reference cannot rank the models</title></line><text x=\"" << right - 4
          << "\" y=\"" << Fixed(py - 4, 1)
          << "\" text-anchor=\"end\" fill=\"#888\" font-size=\"10\">mean reference noise</text>\n";
    }
    // The Pareto front: a staircase through the non-dominated points.
    std::vector<double> cost, error;
    for (const CompareSummary& s : summary) {
        cost.push_back(s.frame_seconds > 0.0 && s.pareto_apart.empty() ? s.frame_seconds
                                                                       : std::nan(""));
        error.push_back(s.mean_flip);
    }
    const std::vector<int> front = ParetoFront(cost, error);
    if (!front.empty()) {
        std::string points;
        for (size_t k = 0; k < front.size(); ++k) {
            const double px = x.Map(cost[front[k]]), py = y.Map(error[front[k]]);
            if (k > 0) points += Fixed(px, 1) + "," + Fixed(y.Map(error[front[k - 1]]), 1) + " ";
            points += Fixed(px, 1) + "," + Fixed(py, 1) + " ";
        }
        points += Fixed(right, 1) + "," + Fixed(y.Map(error[front.back()]), 1);
        std::string names;
        for (int i : front) names += (names.empty() ? "" : ", ") + summary[i].model;
        f << "<polyline points=\"" << points
          << "\" fill=\"none\" stroke=\"#6c6\" stroke-width=\"1.5\"><title>Pareto front: "
          << HtmlEscape(names) << "</title></polyline>\n";
    }
    for (size_t m = 0; m < summary.size(); ++m) {
        const CompareSummary& s = summary[m];
        if (!(s.frame_seconds > 0.0)) continue;
        const double px = x.Map(s.frame_seconds), py = y.Map(s.mean_flip);
        const std::string colour = SeriesColour(m);
        const std::string tip =
            s.model +
            (s.pareto_apart.empty() ? "" : " (apart from the front: " + s.pareto_apart + ")") +
            ": mean FLIP " + General(s.mean_flip, 4) + ", worst " + General(s.worst_flip, 4) +
            " (" + s.worst_view + "), " + Duration(s.frame_seconds) + " per frame" +
            (s.prepare_seconds > 0.0 ? ", precompute " + Duration(s.prepare_seconds)
                                     : std::string()) +
            ", rank " + std::to_string(s.rank);
        f << "<g><title>" << HtmlEscape(tip) << "</title>";
        f << "<line x1=\"" << Fixed(px, 1) << "\" x2=\"" << Fixed(px, 1) << "\" y1=\""
          << Fixed(py, 1) << "\" y2=\"" << Fixed(y.Map(s.worst_flip), 1) << "\" stroke=\"" << colour
          << "\"/><line x1=\"" << Fixed(px - 4, 1) << "\" x2=\"" << Fixed(px + 4, 1) << "\" y1=\""
          << Fixed(y.Map(s.worst_flip), 1) << "\" y2=\"" << Fixed(y.Map(s.worst_flip), 1)
          << "\" stroke=\"" << colour << "\"/>";
        if (s.prepare_seconds > 0.0) {
            const double qx = x.Map(s.prepare_seconds);
            f << "<line x1=\"" << Fixed(px, 1) << "\" x2=\"" << Fixed(qx, 1) << "\" y1=\""
              << Fixed(py, 1) << "\" y2=\"" << Fixed(py, 1) << "\" stroke=\"" << colour
              << "\" stroke-dasharray=\"3 3\" stroke-opacity=\"0.6\"/><path d=\"M" << Fixed(qx, 1)
              << "," << Fixed(py - 6, 1) << " l6,6 l-6,6 l-6,-6 z\" fill=\"none\" "
              << "stroke=\"" << colour << "\"/>";
        }
        // Models apart from the front (a baseline, outside their validity): hollow.
        f << "<circle cx=\"" << Fixed(px, 1) << "\" cy=\"" << Fixed(py, 1) << "\" r=\"5\" fill=\""
          << (s.pareto_apart.empty() ? colour : "none") << "\" stroke=\""
          << (s.pareto_apart.empty() ? "#111" : colour) << "\"/></g>\n";
    }
    // Legend, right of the plot (names next to points would collide).
    for (size_t m = 0; m < summary.size(); ++m) {
        const double ly = top + 14.0 * static_cast<double>(m) + 6;
        f << "<circle cx=\"" << right + 20 << "\" cy=\"" << ly << "\" r=\"4\" fill=\""
          << SeriesColour(m) << "\"/><text x=\"" << right + 30 << "\" y=\"" << ly + 4
          << "\" fill=\"#ccc\" font-size=\"11\">" << HtmlEscape(summary[m].model)
          << (summary[m].pareto ? " *" : "") << (summary[m].pareto_apart.empty() ? "" : " (apart)")
          << "</text>\n";
    }
    f << "<text x=\"" << right + 20 << "\" y=\""
      << top + 14.0 * static_cast<double>(summary.size()) + 14
      << "\" fill=\"#888\" font-size=\"10\">* on the Pareto front (green); hollow, apart: "
         "a baseline or outside its validity</text>\n";
    f << "</svg>\n";
}

// The verdict per regime (regimes.h): the report's first table.
void RegimeTable(std::ostream& f, const CompareConfig& config, const CompareResult& r) {
    const std::vector<RegimeVerdict> verdicts = JudgeRegimes(r);
    if (verdicts.empty()) return;
    const std::string size = std::to_string(config.width) + "x" + std::to_string(config.height);
    f << "<table class=\"summary\" id=\"regimes\"><caption>Which model where: per regime, the "
         "best model(s) by mean FLIP over its views, tied within the reference's mean noise "
         "there (<a href=\"regimes.csv\">regimes.csv</a>); baselines and models outside their "
         "declared validity in a regime's views are left out</caption>\n"
         "<tr><th>regime</th><th>views</th><th>best (ties: =)</th><th>mean FLIP</th>"
         "<th>per frame, "
      << size << ", " << HtmlEscape(CostMachine(config, r))
      << "</th><th>precompute</th><th>reference noise</th><th>left out</th></tr>\n";
    for (const RegimeVerdict& v : verdicts) {
        std::string views, best, flip, frame, pre;
        for (const std::string& x : v.views) views += (views.empty() ? "" : ", ") + x;
        for (size_t k = 0; k < v.best.size(); ++k) {
            const std::string sep = k == 0 ? "" : v.best.size() > 1 ? " = " : ", ";
            best += sep + r.models[static_cast<size_t>(v.best[k])];
            flip += (k ? " / " : "") + Fixed(v.flip[k], 4);
            frame += (k ? " / " : "") + Duration(v.frame_seconds[k]);
            pre += (k ? " / " : "") + (v.precompute_seconds[k] > 0.0
                                           ? Duration(v.precompute_seconds[k])
                                           : std::string("-"));
        }
        std::string excluded;
        for (const std::string& x : v.excluded) excluded += (excluded.empty() ? "" : "; ") + x;
        f << "<tr><th>" << HtmlEscape(v.kind + ": " + v.regime) << "</th><td style=\"text-align:"
          << "left;white-space:normal\">" << HtmlEscape(views) << "</td><td class=\""
          << (v.best.size() > 1 ? "tie" : "best") << "\" style=\"text-align:left\">"
          << HtmlEscape(best.empty() ? std::string("(none eligible)") : best) << "</td><td>" << flip
          << "</td><td>" << frame << "</td><td>" << pre << "</td><td>"
          << (v.reference_noise >= 0.0 ? Fixed(v.reference_noise, 4) : std::string("&ndash;"))
          << "</td><td style=\"text-align:left;white-space:normal\">" << HtmlEscape(excluded)
          << "</td></tr>\n";
    }
    f << "</table>\n";
}

// FLIP over the sky and over the ground per view and model (flip_sky.csv,
// flip_ground.csv), the reference's noise per region beside.
void RegionTable(std::ostream& f, const CompareResult& r) {
    f << "<table class=\"metric\" id=\"regions\"><caption>FLIP over the sky / over the ground "
         "(<a href=\"flip_sky.csv\">flip_sky.csv</a>, <a href=\"flip_ground.csv\">"
         "flip_ground.csv</a>; RMSE in <a href=\"rmse_sky.csv\">rmse_sky.csv</a>, <a "
         "href=\"rmse_ground.csv\">rmse_ground.csv</a>; the reference's noise and mean per "
         "region in <a href=\"reference_noise_regions.csv\">reference_noise_regions.csv</a>)"
         "</caption>\n<tr><th>view</th>";
    for (size_t m = 0; m < r.models.size(); ++m) f << "<th>" << HtmlEscape(r.models[m]) << "</th>";
    f << "<th title=\"ground pixels of the view\">ground share</th><th title=\"the reference's "
         "twice RMS standard error over the sky / the ground, relative to its mean there\">"
         "reference relative noise</th></tr>\n";
    auto value = [](double v) { return std::isfinite(v) ? Fixed(v, 3) : std::string("&ndash;"); };
    for (const CompareRow& row : r.rows) {
        f << "<tr><th>" << HtmlEscape(row.label) << "</th>";
        for (const CompareCell& c : row.cells) {
            f << "<td>" << value(c.flip_sky) << " / " << value(c.flip_ground) << "</td>";
        }
        const double total = static_cast<double>(row.sky_pixels + row.ground_pixels);
        auto relative = [](double noise, double mean) {
            return noise >= 0.0 && mean > 0.0 && std::isfinite(mean)
                       ? General(100.0 * noise / mean, 2) + "%"
                       : std::string("&ndash;");
        };
        f << "<td>" << (total > 0.0 ? Fixed(100.0 * row.ground_pixels / total, 0) + "%" : "")
          << "</td><td>" << relative(row.reference_rmse_noise_sky, row.reference_mean_sky) << " / "
          << relative(row.reference_rmse_noise_ground, row.reference_mean_ground) << "</td></tr>\n";
    }
    f << "</table>\n";
}

// The colour bars of a view's FLIP maps and error images.
void ColourBars(std::ostream& f, const CompareConfig& config, float exposure) {
    const bool transmittance = config.quantity == Quantity::kTransmittance;
    // The error image's display: 1 - exp(-exposure e), sRGB; the bar spans
    // where that is visibly below white.
    const SvgAxis range =
        MakeSvgAxis(0.0, 4.0 / static_cast<double>(std::max(exposure, 1e-12f)), false, 0, 1);
    f << "<svg class=\"plot colourbar\" data-plot=\"colour-bars\" "
         "xmlns=\"http://www.w3.org/2000/svg\" width=\"900\" height=\"52\" role=\"img\" "
         "aria-label=\"colour bars\">\n";
    SvgColourBar(
        f, 10, 16, 360, 0.0, 1.0,
        [](double v, unsigned char rgb[3]) { FlipMagma(static_cast<float>(v), rgb); },
        {0.0, 0.25, 0.5, 0.75, 1.0},
        std::string("FLIP map: ") + (transmittance ? "LDR" : "HDR") +
            "-FLIP per pixel (unitless, 0 to 1)");
    SvgColourBar(
        f, 440, 16, 400, range.lo, range.hi,
        [exposure](double v, unsigned char rgb[3]) {
            rgb[0] = rgb[1] = rgb[2] = EncodeDisplayValue(static_cast<float>(v), exposure);
        },
        range.Ticks(),
        transmittance ? "error image: |model - reference| per channel (transmittance, unitless)"
                      : "error image: |model - reference| per channel (linear radiance units)");
    f << "</svg>\n";
}

// Luminance along one line: the reference with its +-2 sigma band, every model.
void ProfilePlot(std::ostream& f, const CompareRow& row, const CompareRow::Profile& profile,
                 const CompareResult& r, bool luminance) {
    // --luminance: in cd m^-2 (the row's scale).
    CompareRow::Profile p = profile;
    if (luminance) {
        for (double& v : p.reference) v *= row.luminance_scale;
        for (double& v : p.reference_sigma) v *= row.luminance_scale;
        for (auto& m : p.models) {
            for (double& v : m) v *= row.luminance_scale;
        }
    }
    const double left = 62, right = 430, top = 26, bottom = 210;
    // The scale follows the reference: from its smallest positive value (at
    // least 1/1000 of its largest) to the largest value of any line, at most
    // 30 times the reference's largest; lines beyond run along the top edge.
    double ref_hi = 0.0, all_hi = 0.0;
    for (double v : p.reference) ref_hi = std::max(ref_hi, v);
    for (const auto& m : p.models) {
        for (double v : m) all_hi = std::max(all_hi, v);
    }
    if (!(ref_hi > 0.0)) ref_hi = all_hi > 0.0 ? all_hi : 1.0;
    const double hi = std::clamp(all_hi, ref_hi, 30.0 * ref_hi);
    double lo = ref_hi;
    for (double v : p.reference) {
        if (v > 0.0) lo = std::min(lo, v);
    }
    lo = std::max(lo, ref_hi * 1e-3);  // the floor of the log axis
    const std::vector<double>& a = p.line.angle_deg;
    if (a.empty()) return;
    SvgAxis xa = MakeSvgAxis(0.0, 1.0, false, left, right);
    xa.lo = std::min(a.front(), a.back());  // the line's own extent, not from 0
    xa.hi = std::max(a.front(), a.back());
    const SvgAxis y = MakeSvgAxis(lo, hi, true, bottom, top);
    f << "<svg class=\"plot\" data-plot=\"profile\" xmlns=\"http://www.w3.org/2000/svg\" "
         "width=\"610\" height=\""
      << bottom + 40 << "\" role=\"img\" aria-label=\"profile " << HtmlEscape(row.label) << "\">\n"
      << "<title>" << HtmlEscape(row.label + ": luminance along " + p.line.title) << "</title>\n"
      << "<text x=\"" << left << "\" y=\"14\" fill=\"#ddd\" font-size=\"12\">"
      << HtmlEscape(row.label + ": " + p.line.title) << "</text>\n";
    SvgAxes(f, xa, y,
            p.line.vertical ? "angle above the image centre (deg)"
                            : "angle right of the image centre (deg)",
            luminance ? "luminance (cd m^-2, log)" : "luminance (log)");
    auto point = [&](size_t i, double v) {
        return Fixed(xa.Map(a[i]), 1) + "," + Fixed(y.Map(std::max(v, y.lo)), 1);
    };
    if (p.line.marker >= 0 && static_cast<size_t>(p.line.marker) < a.size()) {
        const double px = xa.Map(a[static_cast<size_t>(p.line.marker)]);
        f << "<line x1=\"" << Fixed(px, 1) << "\" x2=\"" << Fixed(px, 1) << "\" y1=\"" << top
          << "\" y2=\"" << bottom << "\" stroke=\"#a84\" stroke-dasharray=\"4 3\"/><text x=\""
          << Fixed(px + 3, 1) << "\" y=\"" << top + 10 << "\" fill=\"#a84\" font-size=\"10\">"
          << HtmlEscape(p.line.marker_label) << "</text>\n";
    }
    if (p.reference_sigma.size() == p.reference.size()) {
        std::string band;
        for (size_t i = 0; i < a.size(); ++i) {
            band += point(i, p.reference[i] + 2.0 * p.reference_sigma[i]) + " ";
        }
        for (size_t i = a.size(); i-- > 0;) {
            band += point(i, p.reference[i] - 2.0 * p.reference_sigma[i]) + " ";
        }
        double mean_rel = 0.0;
        for (size_t i = 0; i < a.size(); ++i) {
            mean_rel += p.reference[i] > 0.0 ? p.reference_sigma[i] / p.reference[i] : 0.0;
        }
        f << "<polygon points=\"" << band
          << "\" fill=\"#fff\" fill-opacity=\"0.25\" stroke=\"none\"><title>reference +-2 "
             "standard deviations (mean relative sigma "
          << General(100.0 * mean_rel / static_cast<double>(a.size()), 3)
          << "%)</title></polygon>\n";
    }
    auto series = [&](const std::vector<double>& v, const std::string& name,
                      const std::string& colour, double width) {
        std::string pts;
        double rel = 0.0;
        int n = 0;
        for (size_t i = 0; i < v.size() && i < a.size(); ++i) {
            pts += point(i, v[i]) + " ";
            if (p.reference[i] > 0.0) {
                rel += std::fabs(v[i] - p.reference[i]) / p.reference[i];
                ++n;
            }
        }
        std::string tip = name + ": luminance " +
                          General(*std::min_element(v.begin(), v.end()), 3) + " to " +
                          General(*std::max_element(v.begin(), v.end()), 3);
        if (&v != &p.reference && n > 0) {
            tip += ", mean |relative difference| to the reference " + General(100.0 * rel / n, 3) +
                   "%";
        }
        f << "<polyline points=\"" << pts << "\" fill=\"none\" stroke=\"" << colour
          << "\" stroke-width=\"" << width << "\"><title>" << HtmlEscape(tip)
          << "</title></polyline>\n";
    };
    for (size_t m = 0; m < p.models.size(); ++m) {
        if (!p.models[m].empty()) series(p.models[m], r.models[m], SeriesColour(m), 1.3);
    }
    if (!p.reference.empty()) series(p.reference, "reference", "#fff", 2.0);
    // Legend.
    f << "<text x=\"" << right + 10 << "\" y=\"" << top + 8
      << "\" fill=\"#fff\" font-size=\"10\">&#8212; reference"
      << (p.reference_sigma.empty() ? "" : " (band &#177;2&#963;)") << "</text>\n";
    for (size_t m = 0; m < p.models.size(); ++m) {
        double peak = 0.0;
        for (double v : p.models[m]) peak = std::max(peak, v);
        f << "<text x=\"" << right + 10 << "\" y=\"" << top + 21 + 13.0 * static_cast<double>(m)
          << "\" fill=\"" << SeriesColour(m) << "\" font-size=\"10\">&#8212; "
          << HtmlEscape(r.models[m]) << (peak > y.hi ? " (off the scale)" : "") << "</text>\n";
    }
    f << "</svg>\n";
}

}  // namespace

void WriteCompareReport(const std::string& path, const CompareConfig& config,
                        const CompareResult& r) {
    TextOutput f(path);
    const bool transmittance = config.quantity == Quantity::kTransmittance;
    const std::string title =
        std::string("atmos compare: ") + (transmittance ? "transmittance" : "radiance");
    f << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>"
      << HtmlEscape(title) << "</title>\n<style>\n"
      << "body{font-family:sans-serif;background:#111;color:#ddd;margin:1.5em}\n"
      << "h1,h2{font-weight:normal}a{color:#8cf}\n"
      << "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #444;padding:"
         "3px 7px;font-size:13px}th{background:#222;font-weight:normal}\n"
      << "td{text-align:right;font-family:monospace;white-space:nowrap}caption{text-align:left;"
         "padding:4px 0}\n"
      << "td.best{background:#274;color:#fff;font-weight:bold}\n"
      << "td.tie{background:#353;color:#eee}\n"
      << "table.summary td{text-align:right;white-space:nowrap}table.summary th{text-align:left}"
         "\n"
      << ".plots{display:flex;flex-wrap:wrap;gap:6px}\n"
      << "td.noise{font-style:italic;color:#888}\ntd.best.noise{color:#cdc}\n"
      << ".row{display:flex;gap:10px;overflow-x:auto;padding-bottom:8px}\n"
      << "figure{margin:0;flex:0 0 auto;width:240px}figure img{width:240px;display:block;"
         "background:#000;margin-bottom:2px}\n"
      << "figcaption{font-size:12px;color:#aaa}figcaption b{color:#fff}.flag{color:#fb4}\n"
      << "dl{display:grid;grid-template-columns:max-content auto;gap:2px 14px;font-size:13px}"
         "dt{color:#999}dd{margin:0}\n"
      << "#image-check{color:#f66}\n"
      << "</style>\n"
      // Records script errors and console.error calls before anything else runs.
      << "<script>\nwindow.atmosErrors = [];\n"
         "window.addEventListener('error', function (e) {\n"
         "  window.atmosErrors.push(e.message || ('cannot load ' + (e.target && "
         "(e.target.src || e.target.href))));\n}, true);\n"
         "(function () { var original = console.error; console.error = function () {\n"
         "  window.atmosErrors.push(Array.prototype.join.call(arguments, ' '));\n"
         "  return original.apply(console, arguments); }; })();\n</script>\n"
      << "</head><body>\n<h1>" << HtmlEscape(title) << "</h1>\n<p id=\"image-check\"></p>\n";
    RegimeTable(f, config, r);

    // Which model? The summary and accuracy against cost.
    const std::vector<CompareSummary> summary = SummarizeCompare(config, r);
    const double mean_noise = MeanReferenceNoise(r);
    f << "<h2>Which model?</h2>\n<p>Accuracy against cost: each model's mean FLIP over the "
         "views (the whisker reaches its worst view) against its render time per frame; a "
         "hollow diamond on the dashed line marks its precomputation time, once per "
         "atmosphere. The green staircase is the Pareto front: no other model is both faster "
         "and more accurate. Hover a mark for its values. Ranks: models whose mean FLIP lies "
         "within ";
    if (mean_noise > 0.0) {
        f << "the mean reference noise (" << General(mean_noise, 3) << ")";
    } else {
        f << "0 (the reference's noise is not measured: only equal values tie)";
    }
    f << " of a rank's first model share its rank (=).</p>\n";
    AccuracyCostPlot(f, config, r, summary);
    SummaryTable(f, config, r, summary);
    f << "<h2>Parameters and machine</h2>\n<dl>\n";
    auto item = [&](const std::string& k, const std::string& v) {
        f << "<dt>" << HtmlEscape(k) << "</dt><dd>" << HtmlEscape(v) << "</dd>\n";
    };
    std::string ref_opts;  // as a model spec: NAME:OPTION=VALUE:...
    for (const auto& [k, v] : config.reference_options) ref_opts += ":" + k + "=" + v;
    item("reference",
         config.reference_model + ref_opts +
             (config.reference_note.empty() ? "" : " (" + config.reference_note + ")"));
    item("quantity", QuantityName(config.quantity));
    item("size", std::to_string(config.width) + "x" + std::to_string(config.height));
    item("atmosphere", config.atmosphere_name);
    const double ppd = config.flip.ppd > 0.0 ? config.flip.ppd : FlipDefaultPpd();
    item("metric", transmittance
                       ? "LDR-FLIP (transmittance as linear RGB in [0, 1]), RMSE"
                       : std::string("HDR-FLIP (tone mapper ") +
                             FlipToneMapperName(config.flip.tone_mapper) +
                             ", exposure range from the reference, black pixels: " +
                             (config.flip.exposure_setup == FlipExposureSetup::kThesis
                                  ? "thesis (1e-9 added to every pixel, Leenman 2025 section 11.5)"
                                  : "atmos (median over non-black pixels)") +
                             "), RMSE over all channels");
    item("pixels per degree", Fixed(ppd, 4));
    item("models", std::to_string(r.models.size()));
    // Each model's options as compared (the defaults unless the spec sets
    // them): the defaults change between rounds (issue 15).
    for (const std::string& m : r.models) {
        std::string opts;
        try {
            const ModelSpec spec = ParseModelSpec(m);
            for (const ModelOptionSpec& o : GetModelInfo(spec.name).options) {
                const auto given = spec.options.find(o.name);
                opts += (opts.empty() ? "" : " ") + o.name + "=" +
                        (given != spec.options.end() ? given->second : o.default_value);
            }
        } catch (const Error&) {
            continue;  // not a registered model spec: nothing to list
        }
        item("options of " + m, opts.empty() ? "(none)" : opts);
    }
    item("views", std::to_string(r.rows.size()));
    if (r.reference_noise_target > 0.0) {
        // Which views' reference reached the noise target (issue 33 item 3).
        std::string reached, missed;
        for (const CompareRow& row : r.rows) {
            const bool ok =
                row.reference_noise >= 0.0 && row.reference_noise <= r.reference_noise_target;
            std::string& list = ok ? reached : missed;
            list += (list.empty() ? "" : ", ") + row.label +
                    (ok ? ""
                        : " (" + Fixed(row.reference_noise, 4) + " at " +
                              std::to_string(row.reference_spp) + " spp)");
        }
        const size_t n_reached =
            reached.empty()
                ? 0
                : static_cast<size_t>(std::count(reached.begin(), reached.end(), ',')) + 1;
        item("reference noise target",
             General(r.reference_noise_target, 3) + ": reached in " + std::to_string(n_reached) +
                 " of " + std::to_string(r.rows.size()) + " views" +
                 (reached.empty() ? "" : " (" + reached + ")") +
                 (missed.empty()
                      ? ""
                      : "; not reached (cap " + std::to_string(config.reference_monte_carlo.spp) +
                            " paths per pixel): " + missed));
    }
    if (config.luminance) item("luminance", config.luminance_note);
    item("command", config.command_line);
    item("CPU", CpuName());
    item("threads", std::to_string(r.threads));
    item("compiler", CompilerName() + ", " + BuildType());
    item("date", UtcNow());
    item("total time", Fixed(r.total_seconds, 1) + " s");
    f << "</dl>\n";

    f << "<h2>Errors against the reference</h2>\n<p>Best per row highlighted (green, bold) only "
         "when its lead over the next model exceeds the reference's noise in that row (FLIP: "
         "the reference noise column; RMSE: twice the reference's RMS standard error); "
         "otherwise every model within that noise of the lowest is marked as tied (=, darker "
         "green). "
         "&dagger;: the view lies outside the model's declared validity (rendered anyway). "
         "Also in <a href=\"flip.csv\">flip.csv</a> and <a href=\"rmse.csv\">rmse.csv</a>.";
    if (!r.rows.empty() && r.rows.front().reference_noise >= 0.0) {
        f << " The path-traced reference is the average of two independent halves; <i>reference "
             "noise</i> is the HDR-FLIP between them (<a href=\"reference_noise.csv\">"
             "reference_noise.csv</a>: the noise reached and the paths per pixel of each view; "
             "with <code>--reference-noise</code> each view renders until it is at or below the "
             "target or reaches the <code>--reference-spp</code> cap), an upper bound of the "
             "reference's own error. A FLIP at or below it (&asymp;, grey) is not resolved by "
             "this reference: lower <code>--reference-noise</code> (or raise the cap) to rank "
             "those models.";
    }
    std::string shipped_views;
    for (const CompareRow& row : r.rows) {
        if (row.reference_source == "shipped")
            shipped_views += (shipped_views.empty() ? "" : ", ") + row.label;
    }
    if (!shipped_views.empty()) {
        f << " Shipped references (not rendered in this run; their provenance, paths per pixel and "
             "noise under each view's reference image): "
          << HtmlEscape(shipped_views) << ".";
    }
    f << "</p>\n";
    MetricTable(f,
                transmittance ? "FLIP errors, transmittance (LDR-FLIP)" : "FLIP errors (HDR-FLIP)",
                6, r, true);
    MetricTable(f, transmittance ? "RMSE errors, transmittance" : "RMSE errors", 8, r, false);
    RegionTable(f, r);
    if (config.luminance) {
        f << "<table class=\"metric\" id=\"luminance\"><caption>Mean luminance over each image, "
             "cd m^-2 (<a href=\"luminance.csv\">luminance.csv</a>: also over the sky and the "
             "ground; "
          << HtmlEscape(config.luminance_note)
          << ")</caption>\n<tr><th>view</th><th>reference</th>";
        for (const std::string& m : r.models) f << "<th>" << HtmlEscape(m) << "</th>";
        f << "</tr>\n";
        for (const CompareRow& row : r.rows) {
            f << "<tr><th>" << HtmlEscape(row.label) << "</th><td>"
              << General(row.reference_luminance.all, 4) << "</td>";
            for (const CompareCell& c : row.cells)
                f << "<td>" << General(c.luminance.all, 4) << "</td>";
            f << "</tr>\n";
        }
        f << "</table>\n";
    }

    f << "<h2>Render times</h2>\n";
    TimeChart(f, config, r);
    f << "<p>Per view and model in <a href=\"times.csv\">times.csv</a>; "
         "<code>atmos bench</code> measures medians of repeated runs.</p>\n";

    f << "<h2>Significant lines of code</h2>\n<p>Counted by the rules of the thesis (Leenman 2025 "
         "section 11.7) over each model's own files; the thesis's counts from its section 12.4."
         "</p>\n<table><tr><th>model</th><th>lines (atmos)</th><th>lines (thesis)</th>"
         "<th>files</th></tr>\n";
    for (size_t i = 0; i < r.loc.size(); ++i) {
        const ModelLoc& l = r.loc[i];
        std::string files;
        for (const std::string& file : l.files) files += (files.empty() ? "" : ", ") + file;
        f << "<tr><th>" << HtmlEscape(l.model) << (i + 1 == r.loc.size() ? " (reference)" : "")
          << "</th><td>" << l.lines << "</td><td>"
          << (l.thesis_lines >= 0 ? std::to_string(l.thesis_lines) + " (" + l.thesis_name + ")"
                                  : std::string("&ndash;"))
          << "</td><td style=\"text-align:left\">" << HtmlEscape(files) << "</td></tr>\n";
    }
    f << "</table>\n";

    f << "<h2>Views</h2>\n<p>Each model: its image, its FLIP error map and its absolute error "
         "(colour bars above each view; hover an image for its values). Below: the luminance "
         "along the image column through the sun and along the row just above the horizon, "
         "reference (white";
    if (!r.rows.empty() && !r.rows.front().profiles.empty() &&
        !r.rows.front().profiles.front().reference_sigma.empty()) {
        f << ", the grey band &plusmn;2 standard deviations of its estimate";
    }
    f << ") against every model, log scale.</p>\n";
    for (const CompareRow& row : r.rows) {
        f << "<h3 id=\"view-" << HtmlEscape(row.view) << "\">" << HtmlEscape(row.label)
          << "</h3><p>" << HtmlEscape(row.description) << "</p>\n";
        ColourBars(f, config, row.exposure);
        f << "<div class=\"row\">\n<figure><img src=\"" << HtmlEscape(row.reference_png)
          << "\" alt=\"reference\" title=\"reference, " << HtmlEscape(row.label)
          << "\"><figcaption><b>reference</b> (" << HtmlEscape(config.reference_model) << ")<br>"
          << (row.reference_source == "shipped"
                  ? "shipped: " + HtmlEscape(row.reference_provenance) + "<br>" +
                        std::to_string(row.reference_spp) + " paths per pixel, noise " +
                        Fixed(row.reference_noise, 4)
                  : Fixed(row.reference_seconds, 3) + " s" +
                        (row.reference_cached ? " (cached)" : ""))
          << "</figcaption></figure>\n";
        for (size_t m = 0; m < row.cells.size(); ++m) {
            const CompareCell& c = row.cells[m];
            const std::string values = "FLIP " + Fixed(c.flip, 6) + ", RMSE " + General(c.rmse, 3);
            f << "<figure><img src=\"" << HtmlEscape(c.image_png) << "\" alt=\""
              << HtmlEscape(r.models[m]) << "\" title=\"" << HtmlEscape(r.models[m] + ": " + values)
              << "\"><img src=\"" << HtmlEscape(c.flip_png) << "\" alt=\"FLIP map\" title=\""
              << HtmlEscape(r.models[m] + ": FLIP map, mean " + Fixed(c.flip, 6))
              << "\"><img src=\"" << HtmlEscape(c.rmse_png) << "\" alt=\"error\" title=\""
              << HtmlEscape(r.models[m] + ": |model - reference|, RMSE " + General(c.rmse, 3))
              << "\"><figcaption><b>" << HtmlEscape(r.models[m]) << "</b><br>FLIP "
              << Fixed(c.flip, 6) << ", RMSE " << General(c.rmse, 3) << "<br>"
              << Fixed(c.render_seconds, 3) + " s" << (c.cached ? " (cached)" : "");
            if (!c.validity_note.empty()) {
                f << "<br><span class=\"flag\">&dagger; " << HtmlEscape(c.validity_note)
                  << "</span>";
            }
            f << "</figcaption></figure>\n";
        }
        f << "</div>\n";
        if (!row.profiles.empty()) {
            f << "<div class=\"plots\">\n";
            for (const CompareRow::Profile& p : row.profiles) {
                ProfilePlot(f, row, p, r, config.luminance);
            }
            f << "</div>\n";
        }
    }
    // Records in the page whether every image loaded (read by the headless-browser test, and
    // a visible warning for a person when some file is missing).
    f << "<script>\nwindow.addEventListener('load', function () {\n"
         "  var plots = document.querySelectorAll('svg.plot');\n"
         "  var imgs = document.images, ok = 0, bad = [];\n"
         "  for (var i = 0; i < imgs.length; ++i) {\n"
         "    if (imgs[i].complete && imgs[i].naturalWidth > 0) ++ok;"
         " else bad.push(imgs[i].getAttribute('src'));\n  }\n"
         "  var p = document.getElementById('image-check');\n"
         "  p.setAttribute('data-loaded', ok);\n"
         "  p.setAttribute('data-total', imgs.length);\n"
         "  p.setAttribute('data-plots', plots.length);\n"
         "  p.setAttribute('data-errors', window.atmosErrors.length);\n"
         "  if (window.atmosErrors.length) bad.push('errors: ' + window.atmosErrors.join('; '));\n"
         "  if (bad.length) p.textContent = 'images that did not load: ' + bad.join(', ');\n"
         "});\n</script>\n";
    f << "</body></html>\n";
    f.Commit();
}

double MeanReferenceNoise(const CompareResult& r) {
    double sum = 0.0;
    int n = 0;
    for (const CompareRow& row : r.rows) {
        if (row.reference_noise < 0.0) return -1.0;
        sum += row.reference_noise;
        ++n;
    }
    return n > 0 ? sum / n : -1.0;
}

std::vector<CompareSummary> SummarizeCompare(const CompareConfig& config, const CompareResult& r) {
    std::vector<CompareSummary> out;
    const double scale = 1920.0 * 1080.0 / (static_cast<double>(config.width) * config.height);
    for (size_t m = 0; m < r.models.size(); ++m) {
        CompareSummary s;
        s.model = r.models[m];
        double sum = 0.0;
        std::vector<std::string> outside;
        for (const CompareRow& row : r.rows) {
            const CompareCell& c = row.cells[m];
            sum += c.flip;
            if (s.worst_view.empty() || c.flip > s.worst_flip) {
                s.worst_flip = c.flip;
                s.worst_view = row.label;
            }
            if (c.within_noise) ++s.unresolved_views;
            if (!c.validity_note.empty()) outside.push_back(row.label);
        }
        const double n = static_cast<double>(std::max<size_t>(1, r.rows.size()));
        s.mean_flip = sum / n;
        bool cached = false;
        s.frame_seconds = MeanSeconds(r, static_cast<int>(m), &cached);
        s.frame_seconds_1080p = s.frame_seconds * scale;
        s.prepare_seconds = PrecomputeSeconds(r, m);
        s.table_bytes = m < r.table_bytes.size() ? r.table_bytes[m] : -1;
        for (const ModelLoc& l : r.loc) {
            if (l.model == r.model_names[m]) {
                s.lines = l.lines;
                break;
            }
        }
        if (!outside.empty()) {
            s.validity = "outside its declared validity in " + std::to_string(outside.size()) +
                         " of " + std::to_string(r.rows.size()) + " views:";
            for (const std::string& v : outside) s.validity += " " + v;
        }
        out.push_back(s);
    }
    std::vector<double> means, times;
    for (size_t m = 0; m < out.size(); ++m) {
        CompareSummary& s = out[m];
        bool baseline = false;
        try {
            baseline = GetModelInfo(r.model_names[m]).capabilities.baseline;
        } catch (const Error&) {
        }
        s.pareto_apart = baseline              ? "a baseline"
                         : !s.validity.empty() ? "outside its declared validity in some views"
                                               : "";
        means.push_back(s.mean_flip);
        times.push_back(s.frame_seconds > 0.0 && s.pareto_apart.empty() ? s.frame_seconds
                                                                        : std::nan(""));
    }
    const std::vector<int> ranks = TiedRanks(means, MeanReferenceNoise(r));
    for (size_t m = 0; m < out.size(); ++m) out[m].rank = ranks[m];
    for (int i : ParetoFront(times, means)) out[static_cast<size_t>(i)].pareto = true;
    return out;
}

void WriteAccuracyCostCsv(const std::string& path, const CompareConfig& config,
                          const CompareResult& result) {
    TextOutput f(path);
    f << "model,mean_flip,worst_flip,worst_view,unresolved_views,frame_seconds,"
         "frame_seconds_1920x1080,prepare_seconds,table_bytes,lines_of_code,rank,pareto,"
         "validity\n";
    for (const CompareSummary& s : SummarizeCompare(config, result)) {
        f << s.model << "," << General(s.mean_flip, 8) << "," << General(s.worst_flip, 8) << ","
          << s.worst_view << "," << s.unresolved_views << "," << General(s.frame_seconds, 6) << ","
          << General(s.frame_seconds_1080p, 6) << "," << General(s.prepare_seconds, 6) << ","
          << s.table_bytes << "," << s.lines << "," << s.rank << "," << (s.pareto ? 1 : 0) << ",\""
          << s.validity << "\"\n";
    }
    f.Commit();
}

}  // namespace atmos
