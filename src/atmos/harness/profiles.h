// atmos: radiance profiles of `atmos compare` (issue 22 item 4): per view, the
// luminance along the image column through the sun and along the image row
// just above the horizon, for the reference (with its noise band) and every
// model, drawn as SVG line plots in the report.
#pragma once

#include <string>
#include <vector>

#include "atmos/image.h"
#include "atmos/view.h"

namespace atmos {

struct ProfileLine {
    bool vertical = true;  // an image column (true) or row
    int index = 0;         // the column or row
    std::string title;     // which line and why
    // Per sample along the line (rows top -> bottom, or columns left -> right):
    // the angle of the pixel's ray from the image centre in the camera's
    // vertical (column) or horizontal (row) plane, degrees (+: up, right).
    std::vector<double> angle_deg;
    // Where the other line crosses this one (the horizon's row on the column,
    // the sun's column on the row), as an index along the line; -1: none.
    int marker = -1;
    std::string marker_label;
};

// The two lines of a view of `width` x `height` pixels: the column through
// the sun (the centre column when the sun is behind the camera or outside the
// frame's width) and the row just above the horizon in that column (the row
// above the first one, from the top, whose ray meets the ground sphere of
// radius bottom_radius; the top or bottom row when the horizon is outside the
// frame). Where the atmosphere's shell at the limb is under 3 pixels thick
// (a camera far above top_radius) the row above the limb sees black space: the
// centre row instead, across the planet.
std::vector<ProfileLine> ViewProfileLines(const View& view, int width, int height,
                                          double bottom_radius, double top_radius);

// Linear luminance (Rec. 709: 0.2126 R + 0.7152 G + 0.0722 B) along the line.
std::vector<double> ProfileLuminance(const Image& image, const ProfileLine& line);
// The standard deviation of that luminance from a per-channel variance image,
// the channels taken as fully correlated (the path tracer's channels share
// their paths): sum of w_c sqrt(var_c), an upper bound.
std::vector<double> ProfileSigma(const Image& variance, const ProfileLine& line);

}  // namespace atmos
