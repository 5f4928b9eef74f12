// atmos: small inline-SVG plotting helpers for the compare report (issue 22):
// linear or logarithmic axes with readable ticks, a plot frame with grid and
// labels, and colour bars. Plain text output, no scripts, no fonts from the
// network; every mark the report draws carries a <title> (the browser's hover
// text) with its values.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace atmos {

// A number for an SVG attribute or a label: up to `digits` significant digits,
// no exponent for ordinary magnitudes.
std::string SvgNumber(double v, int digits = 4);

// One axis: data range [lo, hi] (log: both > 0) mapped to pixels [px0, px1].
struct SvgAxis {
    double lo = 0.0, hi = 1.0;
    bool log = false;
    double px0 = 0.0, px1 = 100.0;
    double Map(double v) const;  // data -> pixel (clamped to the range)
    // Tick values inside [lo, hi]: 1-2-5 steps (linear) or the decades
    // (log; with 2 and 5 between when the range spans few decades).
    std::vector<double> Ticks() const;
};

// An axis covering [min, max] of the data: linear from 0 (or min when it is
// negative) to a rounded max, or log from the decade below min to the decade
// above max (min, max > 0; a degenerate range is widened).
SvgAxis MakeSvgAxis(double min, double max, bool log, double px0, double px1);

// Grid, ticks, tick labels and axis labels of a plot whose axes are x and y
// (pixels of x: left -> right, of y: bottom -> top).
// y_ticks false: the frame and the x axis only (the y axis carries names).
void SvgAxes(std::ostream& f, const SvgAxis& x, const SvgAxis& y, const std::string& x_label,
             const std::string& y_label, bool y_ticks = true);

// A horizontal colour bar (width x 14 pixels at (x, y)) for values in [lo, hi]
// coloured by `colour` (value -> 8-bit sRGB), with ticks at `ticks` and a
// label (what and its units) above it. Sampled at 32 gradient stops.
void SvgColourBar(std::ostream& f, double x, double y, double width, double lo, double hi,
                  const std::function<void(double, unsigned char[3])>& colour,
                  const std::vector<double>& ticks, const std::string& label);

// "#rrggbb"
std::string SvgColour(const unsigned char rgb[3]);

// A distinct colour for series i (a fixed, colour-blind friendly palette).
const char* SeriesColour(size_t i);

}  // namespace atmos
