// atmos: the HTML report of `atmos compare` (see report.h).
#include "harness/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "atmos/error.h"
#include "harness/html.h"
#include "harness/machine.h"

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
    const bool noise = flip && !r.rows.empty() && r.rows.front().reference_noise >= 0.0;
    if (noise) {
        f << "<th title=\"HDR-FLIP between the reference's two independent halves\">reference "
             "noise</th>";
    }
    f << "</tr>\n";
    for (const CompareRow& row : r.rows) {
        std::vector<double> values;
        for (const CompareCell& c : row.cells) values.push_back(flip ? c.flip : c.rmse);
        const int best = BestIndex(values);
        f << "<tr><th>" << HtmlEscape(row.label) << "</th>";
        for (size_t m = 0; m < row.cells.size(); ++m) {
            const CompareCell& c = row.cells[m];
            const bool is_best = static_cast<int>(m) == best;
            const bool unresolved = flip && c.within_noise;
            std::string tip = c.validity_note;
            if (unresolved) {
                tip += std::string(tip.empty() ? "" : "; ") +
                       "at or below the reference's own noise: not resolved";
            }
            f << "<td";
            if (is_best || unresolved) {
                f << " class=\"" << (is_best ? "best" : "") << (is_best && unresolved ? " " : "")
                  << (unresolved ? "noise" : "") << "\"";
            }
            if (!tip.empty()) f << " title=\"" << HtmlEscape(tip) << "\"";
            f << ">" << Fixed(values[m], digits) << (c.validity_note.empty() ? "" : " &dagger;")
              << (unresolved ? " &asymp;" : "") << "</td>";
        }
        if (noise) f << "<td class=\"noise\">" << Fixed(row.reference_noise, digits) << "</td>";
        f << "</tr>\n";
    }
    f << "</table>\n";
}

// Horizontal bars: mean render time per view for the reference and each model,
// with the precomputation time as text.
void TimeChart(std::ostream& f, const CompareConfig& config, const CompareResult& r) {
    struct Bar {
        std::string name;
        double mean_ms;
        double prepare_ms;
        bool cached;
    };
    std::vector<Bar> bars;
    auto mean = [&](int m) {
        double sum = 0.0;
        bool cached = false;
        for (const CompareRow& row : r.rows) {
            sum += m < 0 ? row.reference_seconds : row.cells[static_cast<size_t>(m)].render_seconds;
            cached |= m < 0 ? row.reference_cached : row.cells[static_cast<size_t>(m)].cached;
        }
        return std::make_pair(1000.0 * sum / std::max<size_t>(1, r.rows.size()), cached);
    };
    {
        const auto [ms, cached] = mean(-1);
        bars.push_back({"reference (" + config.reference_model + ")", ms,
                        1000.0 * r.reference_prepare_seconds, cached});
    }
    for (size_t m = 0; m < r.models.size(); ++m) {
        const auto [ms, cached] = mean(static_cast<int>(m));
        bars.push_back({r.models[m], ms, 1000.0 * r.prepare_seconds[m], cached});
    }
    double max_ms = 1e-9;
    for (const Bar& b : bars) max_ms = std::max(max_ms, b.mean_ms);
    const int label_w = 220, bar_w = 520, row_h = 26;
    const int height = row_h * static_cast<int>(bars.size()) + 30;
    f << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << label_w + bar_w + 480
      << "\" height=\"" << height << "\" role=\"img\" aria-label=\"render times\">\n";
    for (size_t i = 0; i < bars.size(); ++i) {
        const Bar& b = bars[i];
        const int y = static_cast<int>(i) * row_h + 4;
        const double w = std::max(1.0, bar_w * b.mean_ms / max_ms);
        f << "<text x=\"" << label_w - 8 << "\" y=\"" << y + 16
          << "\" text-anchor=\"end\" fill=\"#ddd\" font-size=\"13\">" << HtmlEscape(b.name)
          << "</text>";
        f << "<rect x=\"" << label_w << "\" y=\"" << y << "\" width=\"" << Fixed(w, 1)
          << "\" height=\"" << row_h - 8 << "\" fill=\"" << (i == 0 ? "#c96" : "#59c") << "\"/>";
        std::string text = Fixed(b.mean_ms, 1) + " ms";
        if (b.prepare_ms > 0.0) text += " + prepare " + Fixed(b.prepare_ms, 1) + " ms";
        if (b.cached) text += " (cached: the time of the original render)";
        f << "<text x=\"" << label_w + w + 6 << "\" y=\"" << y + 15
          << "\" fill=\"#bbb\" font-size=\"12\">" << HtmlEscape(text) << "</text>\n";
    }
    f << "<text x=\"" << label_w << "\" y=\"" << height - 6
      << "\" fill=\"#888\" font-size=\"12\">mean render time per view, " << config.width << "x"
      << config.height << ", " << r.threads << " threads</text>\n";
    f << "</svg>\n";
}

}  // namespace

void WriteCompareReport(const std::string& path, const CompareConfig& config,
                        const CompareResult& r) {
    std::ofstream f(path);
    if (!f) Fail("cannot write '", path, "'");
    const bool transmittance = config.quantity == Quantity::kTransmittance;
    const std::string title =
        std::string("atmos compare: ") + (transmittance ? "transmittance" : "radiance");
    f << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>"
      << HtmlEscape(title) << "</title>\n<style>\n"
      << "body{font-family:sans-serif;background:#111;color:#ddd;margin:1.5em}\n"
      << "h1,h2{font-weight:normal}a{color:#8cf}\n"
      << "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #444;padding:"
         "3px 7px;font-size:13px}th{background:#222;font-weight:normal}\n"
      << "td{text-align:right;font-family:monospace}caption{text-align:left;padding:4px 0}\n"
      << "td.best{background:#274;color:#fff;font-weight:bold}\n"
      << "td.noise{font-style:italic;color:#888}\ntd.best.noise{color:#cdc}\n"
      << ".row{display:flex;gap:10px;overflow-x:auto;padding-bottom:8px}\n"
      << "figure{margin:0;flex:0 0 auto;width:240px}figure img{width:240px;display:block;"
         "background:#000;margin-bottom:2px}\n"
      << "figcaption{font-size:12px;color:#aaa}figcaption b{color:#fff}.flag{color:#fb4}\n"
      << "dl{display:grid;grid-template-columns:max-content auto;gap:2px 14px;font-size:13px}"
         "dt{color:#999}dd{margin:0}\n"
      << "#image-check{color:#f66}\n"
      << "</style></head><body>\n<h1>" << HtmlEscape(title) << "</h1>\n";

    f << "<h2>Parameters and machine</h2>\n<dl>\n";
    auto item = [&](const std::string& k, const std::string& v) {
        f << "<dt>" << HtmlEscape(k) << "</dt><dd>" << HtmlEscape(v) << "</dd>\n";
    };
    std::string ref_opts;
    for (const auto& [k, v] : config.reference_options) {
        ref_opts += (ref_opts.empty() ? "" : " ") + std::string("--") + k + " " + v;
    }
    item("reference",
         config.reference_model + (ref_opts.empty() ? "" : " " + ref_opts) +
             (config.reference_note.empty() ? "" : " (" + config.reference_note + ")"));
    item("quantity", QuantityName(config.quantity));
    item("size", std::to_string(config.width) + "x" + std::to_string(config.height));
    item("atmosphere", config.atmosphere_name);
    const double ppd = config.flip.ppd > 0.0 ? config.flip.ppd : FlipDefaultPpd();
    item("metric", transmittance ? "LDR-FLIP (transmittance as linear RGB in [0, 1]), RMSE"
                                 : std::string("HDR-FLIP (tone mapper ") +
                                       FlipToneMapperName(config.flip.tone_mapper) +
                                       ", exposure range from the reference, black pixels: " +
                                       (config.flip.exposure_setup == FlipExposureSetup::kThesis
                                            ? "thesis (1e-9 added to every pixel, seed 003 11.5)"
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
    item("command", config.command_line);
    item("CPU", CpuName());
    item("threads", std::to_string(r.threads));
    item("compiler", CompilerName() + ", " + BuildType());
    item("date", UtcNow());
    item("total time", Fixed(r.total_seconds, 1) + " s");
    f << "</dl>\n<p id=\"image-check\"></p>\n";

    f << "<h2>Errors against the reference</h2>\n<p>Lowest value per row highlighted. "
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
    f << "</p>\n";
    MetricTable(f,
                transmittance ? "FLIP errors, transmittance (LDR-FLIP)" : "FLIP errors (HDR-FLIP)",
                6, r, true);
    MetricTable(f, transmittance ? "RMSE errors, transmittance" : "RMSE errors", 8, r, false);

    f << "<h2>Render times</h2>\n";
    TimeChart(f, config, r);
    f << "<p>Per view and model in <a href=\"times.csv\">times.csv</a>; "
         "<code>atmos bench</code> measures medians of repeated runs.</p>\n";

    f << "<h2>Significant lines of code</h2>\n<p>Counted by the rules of the thesis (seed 003 "
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

    f << "<h2>Views</h2>\n<p>Each model: its image, its FLIP error map (magma: black = no "
         "error, yellow = 1) and its absolute error (shown with the view's exposure).</p>\n";
    for (const CompareRow& row : r.rows) {
        f << "<h3>" << HtmlEscape(row.label) << "</h3><p>" << HtmlEscape(row.description)
          << "</p>\n"
          << "<div class=\"row\">\n<figure><img src=\"" << HtmlEscape(row.reference_png)
          << "\" alt=\"reference\"><figcaption><b>reference</b> ("
          << HtmlEscape(config.reference_model) << ")<br>" << Fixed(row.reference_seconds, 3) + " s"
          << (row.reference_cached ? " (cached)" : "") << "</figcaption></figure>\n";
        for (size_t m = 0; m < row.cells.size(); ++m) {
            const CompareCell& c = row.cells[m];
            f << "<figure><img src=\"" << HtmlEscape(c.image_png) << "\" alt=\""
              << HtmlEscape(r.models[m]) << "\"><img src=\"" << HtmlEscape(c.flip_png)
              << "\" alt=\"FLIP map\"><img src=\"" << HtmlEscape(c.rmse_png)
              << "\" alt=\"error\"><figcaption><b>" << HtmlEscape(r.models[m]) << "</b><br>FLIP "
              << Fixed(c.flip, 6) << ", RMSE " << General(c.rmse, 3) << "<br>"
              << Fixed(c.render_seconds, 3) + " s" << (c.cached ? " (cached)" : "");
            if (!c.validity_note.empty()) {
                f << "<br><span class=\"flag\">&dagger; " << HtmlEscape(c.validity_note)
                  << "</span>";
            }
            f << "</figcaption></figure>\n";
        }
        f << "</div>\n";
    }
    // Records in the page whether every image loaded (read by the headless-browser test, and
    // a visible warning for a person when some file is missing).
    f << "<script>\nwindow.addEventListener('load', function () {\n"
         "  var imgs = document.images, ok = 0, bad = [];\n"
         "  for (var i = 0; i < imgs.length; ++i) {\n"
         "    if (imgs[i].complete && imgs[i].naturalWidth > 0) ++ok;"
         " else bad.push(imgs[i].getAttribute('src'));\n  }\n"
         "  var p = document.getElementById('image-check');\n"
         "  p.setAttribute('data-loaded', ok);\n"
         "  p.setAttribute('data-total', imgs.length);\n"
         "  if (bad.length) p.textContent = 'images that did not load: ' + bad.join(', ');\n"
         "});\n</script>\n";
    f << "</body></html>\n";
    if (!f) Fail("cannot write '", path, "'");
}

}  // namespace atmos
