// atmos: the honest ranking of `atmos compare` (issue 22).
//
// A model is "best" in a row of the metric tables only when its lead over the
// next one is larger than the reference's own noise in that row; models whose
// value lies within the noise of the lowest are tied and marked together.
// Over the whole table the same rule gives ranks: sorted by value, a rank
// group starts at the lowest value not yet ranked and holds every model
// within `noise` of it (so 0.010, 0.012, 0.030 with noise 0.005 rank 1, 1, 3).
// The accuracy-against-cost plot draws the Pareto front of (time, error).
#pragma once

#include <vector>

namespace atmos {

// Competition ranks (1-based; tied models share a rank, the next rank skips
// them) of `values` (lower is better) with ties within `noise` of a group's
// first value; noise < 0 is taken as 0 (only equal values tie). Non-finite
// values get rank 0 (unranked).
std::vector<int> TiedRanks(const std::vector<double>& values, double noise);

// The row's best: the indices of every model within `noise` of the lowest
// finite value (rank 1 of TiedRanks), in index order. One index: a resolved
// best; more: a tie; none: no finite value.
std::vector<int> BestOfRow(const std::vector<double>& values, double noise);

// The Pareto front of points (cost, error), both lower is better: the indices
// of the points no other point dominates (another point at most as costly and
// at most as wrong, better in one), ordered by cost. Non-finite points are
// left out.
std::vector<int> ParetoFront(const std::vector<double>& cost, const std::vector<double>& error);

}  // namespace atmos
