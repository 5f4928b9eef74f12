// atmos: radiance profiles of `atmos compare` (see profiles.h).
#include "harness/profiles.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace atmos {

namespace {

constexpr double kWeights[3] = {0.2126, 0.7152, 0.0722};
constexpr double kDeg = 180.0 / 3.14159265358979323846;

std::string Degrees(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", v);
    return buf;
}

const float* Pixel(const Image& image, const ProfileLine& line, int i) {
    const int x = line.vertical ? line.index : i;
    const int y = line.vertical ? i : line.index;
    return image.data() + 3 * (static_cast<size_t>(y) * image.width() + x);
}

int Samples(const Image& image, const ProfileLine& line) {
    return line.vertical ? image.height() : image.width();
}

}  // namespace

std::vector<ProfileLine> ViewProfileLines(const View& view, int width, int height,
                                          double bottom_radius, double top_radius) {
    const Camera& c = view.camera;
    const double aspect = static_cast<double>(width) / height;
    const double tan_x = c.tan_half_fov_y * aspect;

    // The sun's column, when the sun is in front of the camera and within the
    // frame's width; else the centre column.
    const Vec3d& d = view.sun_direction;
    const double dz = Dot(d, c.forward);
    double sun_x = -1.0;
    bool above_or_below = false;
    if (dz > 0.0) {
        const double u = Dot(d, c.right) / dz / tan_x;
        const double v = Dot(d, c.up) / dz / c.tan_half_fov_y;
        if (std::fabs(u) <= 1.0) sun_x = 0.5 * (u + 1.0) * width;
        above_or_below = std::fabs(v) > 1.0;
    }
    const bool sun_column = sun_x >= 0.0;
    const int column =
        sun_column ? std::clamp(static_cast<int>(std::floor(sun_x)), 0, width - 1) : width / 2;

    // The row just above the horizon (or the planet's limb seen from space) in
    // that column: the row above the first one, from the top, whose ray passes
    // below the tangent to the ground sphere (elevation < -acos(R / r)).
    const double r = Length(c.position);
    const Vec3d up = c.position / r;
    const double horizon_sin =
        r > bottom_radius ? -std::sqrt(1.0 - std::pow(bottom_radius / r, 2)) : 0.0;
    int hit = height;  // the first row that sees the ground
    for (int y = 0; y < height && hit == height; ++y) {
        if (Dot(c.RayDirection(column, y, width, height), up) <= horizon_sin) hit = y;
    }
    int row = hit - 1;
    std::string row_why;
    const bool horizon_in_frame = hit > 0 && hit < height;
    if (hit == 0) {
        row = 0;
        row_why = "top row (the horizon is above the frame)";
    } else if (hit == height) {
        row_why = "bottom row (the horizon is below the frame)";
    } else {
        row_why = "row " + std::to_string(row) + ", just above the horizon";
    }
    // Far above the atmosphere its shell at the limb is thinner than 3 pixels
    // and the row above the limb sees black space: the centre row (across the
    // planet) instead.
    const double pixel = 2.0 * std::atan(c.tan_half_fov_y) / height;
    const bool outside =
        r > top_radius && std::acos(bottom_radius / r) - std::acos(top_radius / r) < 3.0 * pixel;
    if (outside) {
        row = height / 2;
        row_why = "row " + std::to_string(row) +
                  ", the centre (the atmosphere at the limb is under 3 pixels thick)";
    }

    ProfileLine vertical;
    vertical.vertical = true;
    vertical.index = column;
    vertical.title = "column " + std::to_string(column) +
                     (!sun_column      ? ", the centre (the sun is outside the frame's width)"
                      : above_or_below ? ", the sun's (the sun is above or below the frame)"
                                       : ", through the sun");
    for (int y = 0; y < height; ++y) {
        const double v = (1.0 - 2.0 * (y + 0.5) / height) * c.tan_half_fov_y;
        vertical.angle_deg.push_back(std::atan(v) * kDeg);
    }
    if (horizon_in_frame) {
        vertical.marker = row;
        vertical.marker_label = "horizon";
    }

    ProfileLine horizontal;
    horizontal.vertical = false;
    horizontal.index = row;
    horizontal.title = row_why;
    for (int x = 0; x < width; ++x) {
        const double u = (2.0 * (x + 0.5) / width - 1.0) * tan_x;
        horizontal.angle_deg.push_back(std::atan(u) * kDeg);
    }
    if (sun_column) {
        horizontal.marker = column;
        horizontal.marker_label = "sun's column";
    }
    if (horizon_in_frame && !outside) {
        horizontal.title +=
            " (" +
            Degrees(std::asin(std::clamp(Dot(c.RayDirection(column, row, width, height), up), -1.0,
                                         1.0)) *
                    kDeg) +
            " deg elevation in that column)";
    }
    return {vertical, horizontal};
}

std::vector<double> ProfileLuminance(const Image& image, const ProfileLine& line) {
    std::vector<double> out;
    for (int i = 0; i < Samples(image, line); ++i) {
        const float* p = Pixel(image, line, i);
        out.push_back(kWeights[0] * static_cast<double>(p[0]) +
                      kWeights[1] * static_cast<double>(p[1]) +
                      kWeights[2] * static_cast<double>(p[2]));
    }
    return out;
}

std::vector<double> ProfileSigma(const Image& variance, const ProfileLine& line) {
    std::vector<double> out;
    for (int i = 0; i < Samples(variance, line); ++i) {
        const float* p = Pixel(variance, line, i);
        double s = 0.0;
        for (int ch = 0; ch < 3; ++ch)
            s += kWeights[ch] * std::sqrt(std::max(0.0, static_cast<double>(p[ch])));
        out.push_back(s);
    }
    return out;
}

}  // namespace atmos
