// atmos: the verdict per regime of `atmos compare` (issue 33 item 3):
// regimes.csv and the report's first table.
//
// A view's regimes come from its geometry, so custom views get them too:
// - place, from the camera's altitude above the ground: "ground" (below
//   1 km), "aircraft" (below the atmosphere's top), "orbit" (above it, less
//   than one planet radius up), "space" (farther);
// - light, from the sun's elevation e at the point of the view's centre ray
//   nearest the planet (where it meets the ground, the tangent point, or the
//   camera; world-aligned projections: the camera): "day" (e >= 10 degrees),
//   "sunrise" (0 <= e < 10), and with the sun below the horizon "twilight"
//   when the view looks toward the sun's side (its horizontal direction
//   within 90 degrees of the sun's), else "planet shadow".
// Per regime, the models eligible (not a baseline, inside their declared
// validity in every view of the regime) are ranked by their mean FLIP over
// the regime's views with ties within the mean reference noise of those views
// (ranking.h); the best are those of rank 1.
#pragma once

#include <string>
#include <vector>

#include "harness/compare.h"

namespace atmos {

std::string PlaceRegime(const View& view, const AtmosphereParameters& atmosphere);
std::string LightRegime(const View& view, const AtmosphereParameters& atmosphere);
// The regimes in the table's order.
const std::vector<std::string>& PlaceRegimes();
const std::vector<std::string>& LightRegimes();

struct RegimeVerdict {
    std::string kind;    // "place" or "light"
    std::string regime;  // e.g. "ground", "twilight"
    std::vector<std::string> views;
    std::vector<int> best;                   // model indices (CompareResult::models), rank 1
    std::vector<double> flip;                // each best model's mean FLIP over the views
    std::vector<double> frame_seconds;       // its mean render time per view
    std::vector<double> precompute_seconds;  // its Prepare() seconds (0: none)
    double reference_noise = -1.0;           // the mean over the views (< 0: not measured)
    std::vector<std::string> excluded;       // models left out, with why
};

// One verdict per regime present in the result (place regimes, then light).
std::vector<RegimeVerdict> JudgeRegimes(const CompareResult& result);
// The cost column's machine: "CPU, N threads" or "CUDA GPU".
std::string CostMachine(const CompareConfig& config, const CompareResult& result);
// regimes.csv: kind,regime,views,best,flip,frame_seconds,precompute_seconds,
// machine,reference_noise,excluded (lists separated by spaces; the best's
// numbers in the same order).
void WriteRegimesCsv(const std::string& path, const CompareConfig& config,
                     const CompareResult& result);

}  // namespace atmos
