// atmos: inline-SVG plotting helpers (see svg.h).
#include "harness/svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "harness/html.h"

namespace atmos {

std::string SvgNumber(double v, int digits) {
    if (!std::isfinite(v)) return "0";
    if (v == 0.0) return "0";
    std::ostringstream os;
    const double a = std::fabs(v);
    if (a >= 1e-4 && a < 1e7) {
        // Fixed notation with `digits` significant digits, trailing zeros dropped.
        const int decimals = std::max(0, digits - 1 - static_cast<int>(std::floor(std::log10(a))));
        os.setf(std::ios::fixed);
        os.precision(std::min(decimals, 10));
        os << v;
        std::string s = os.str();
        if (s.find('.') != std::string::npos) {
            while (!s.empty() && s.back() == '0') s.pop_back();
            if (!s.empty() && s.back() == '.') s.pop_back();
        }
        return s;
    }
    os.precision(digits);
    os << v;
    return os.str();
}

double SvgAxis::Map(double v) const {
    double t;
    if (log) {
        const double c = std::clamp(v, lo, hi);
        t = (std::log10(c) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
    } else {
        t = (std::clamp(v, lo, hi) - lo) / (hi - lo);
    }
    if (!std::isfinite(t)) t = 0.0;
    return px0 + t * (px1 - px0);
}

namespace {

double NiceStep(double range, int target) {
    const double raw = range / std::max(1, target);
    const double decade = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0, 10.0}) {
        if (m * decade >= raw) return m * decade;
    }
    return 10.0 * decade;
}

}  // namespace

std::vector<double> SvgAxis::Ticks() const {
    std::vector<double> ticks;
    if (log) {
        const int d0 = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
        const int d1 = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
        const bool fine = d1 - d0 <= 3;
        for (int d = d0; d <= d1; ++d) {
            for (double m : {1.0, 2.0, 5.0}) {
                if (m != 1.0 && !fine) continue;
                const double v = m * std::pow(10.0, d);
                if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) ticks.push_back(v);
            }
        }
        return ticks;
    }
    const double step = NiceStep(hi - lo, 5);
    for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) {
        ticks.push_back(std::fabs(v) < 1e-12 * step ? 0.0 : v);
    }
    return ticks;
}

SvgAxis MakeSvgAxis(double min, double max, bool log, double px0, double px1) {
    SvgAxis a;
    a.log = log;
    a.px0 = px0;
    a.px1 = px1;
    if (!std::isfinite(min) || !std::isfinite(max)) min = max = log ? 1.0 : 0.0;
    if (log) {
        min = std::max(min, 1e-12);
        max = std::max(max, min);
        a.lo = std::pow(10.0, std::floor(std::log10(min)));
        a.hi = std::pow(10.0, std::ceil(std::log10(max)));
        if (a.hi <= a.lo) a.hi = a.lo * 10.0;
        return a;
    }
    a.lo = std::min(0.0, min);
    double hi = std::max(max, a.lo);
    if (hi <= a.lo) hi = a.lo + 1.0;
    const double step = NiceStep(hi - a.lo, 5);
    a.hi = std::ceil(hi / step - 1e-9) * step;
    if (a.hi <= a.lo) a.hi = a.lo + step;
    return a;
}

void SvgAxes(std::ostream& f, const SvgAxis& x, const SvgAxis& y, const std::string& x_label,
             const std::string& y_label, bool y_ticks) {
    const double left = std::min(x.px0, x.px1), right = std::max(x.px0, x.px1);
    const double top = std::min(y.px0, y.px1), bottom = std::max(y.px0, y.px1);
    f << "<g font-size=\"11\" fill=\"#aaa\">\n";
    for (double v : x.Ticks()) {
        const double px = x.Map(v);
        f << "<line x1=\"" << SvgNumber(px, 6) << "\" y1=\"" << top << "\" x2=\""
          << SvgNumber(px, 6) << "\" y2=\"" << bottom << "\" stroke=\"#333\"/>"
          << "<text x=\"" << SvgNumber(px, 6) << "\" y=\"" << bottom + 14
          << "\" text-anchor=\"middle\">" << SvgNumber(v, 3) << "</text>\n";
    }
    for (double v : y_ticks ? y.Ticks() : std::vector<double>()) {
        const double py = y.Map(v);
        f << "<line x1=\"" << left << "\" y1=\"" << SvgNumber(py, 6) << "\" x2=\"" << right
          << "\" y2=\"" << SvgNumber(py, 6) << "\" stroke=\"#333\"/>"
          << "<text x=\"" << left - 5 << "\" y=\"" << SvgNumber(py + 4, 6)
          << "\" text-anchor=\"end\">" << SvgNumber(v, 3) << "</text>\n";
    }
    f << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << right - left << "\" height=\""
      << bottom - top << "\" fill=\"none\" stroke=\"#777\"/>\n";
    f << "<text x=\"" << (left + right) / 2 << "\" y=\"" << bottom + 32
      << "\" text-anchor=\"middle\" fill=\"#ddd\" font-size=\"12\">" << HtmlEscape(x_label)
      << "</text>\n";
    f << "<text transform=\"translate(" << left - 46 << "," << (top + bottom) / 2
      << ") rotate(-90)\" text-anchor=\"middle\" fill=\"#ddd\" font-size=\"12\">"
      << HtmlEscape(y_label) << "</text>\n</g>\n";
}

std::string SvgColour(const unsigned char rgb[3]) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
    return buf;
}

void SvgColourBar(std::ostream& f, double x, double y, double width, double lo, double hi,
                  const std::function<void(double, unsigned char[3])>& colour,
                  const std::vector<double>& ticks, const std::string& label) {
    static int counter = 0;
    const std::string id = "atmos-bar-" + std::to_string(++counter);
    f << "<defs><linearGradient id=\"" << id << "\" x1=\"0\" x2=\"1\" y1=\"0\" y2=\"0\">";
    const int stops = 32;
    for (int i = 0; i <= stops; ++i) {
        const double t = static_cast<double>(i) / stops;
        unsigned char rgb[3];
        colour(lo + t * (hi - lo), rgb);
        f << "<stop offset=\"" << SvgNumber(t, 4) << "\" stop-color=\"" << SvgColour(rgb) << "\"/>";
    }
    f << "</linearGradient></defs>\n";
    f << "<text x=\"" << x << "\" y=\"" << y - 4 << "\" fill=\"#ddd\" font-size=\"11\">"
      << HtmlEscape(label) << "</text>\n";
    f << "<rect x=\"" << x << "\" y=\"" << y << "\" width=\"" << width
      << "\" height=\"14\" fill=\"url(#" << id << ")\" stroke=\"#777\"><title>" << HtmlEscape(label)
      << ": " << SvgNumber(lo) << " to " << SvgNumber(hi) << "</title></rect>\n";
    for (double v : ticks) {
        const double px = x + width * (v - lo) / (hi - lo);
        f << "<line x1=\"" << SvgNumber(px, 6) << "\" y1=\"" << y + 14 << "\" x2=\""
          << SvgNumber(px, 6) << "\" y2=\"" << y + 18 << "\" stroke=\"#aaa\"/><text x=\""
          << SvgNumber(px, 6) << "\" y=\"" << y + 29
          << "\" text-anchor=\"middle\" fill=\"#aaa\" font-size=\"10\">" << SvgNumber(v, 3)
          << "</text>\n";
    }
}

const char* SeriesColour(size_t i) {
    // Okabe & Ito's colour-blind safe palette, then a few more.
    static const char* kColours[] = {"#56b4e9", "#e69f00", "#009e73", "#f0e442",
                                     "#cc79a7", "#d55e00", "#0072b2", "#b3de69",
                                     "#bc80bd", "#80b1d3", "#fdb462", "#fb8072"};
    return kColours[i % (sizeof kColours / sizeof kColours[0])];
}

}  // namespace atmos
