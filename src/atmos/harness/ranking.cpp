// atmos: the honest ranking of `atmos compare` (see ranking.h).
#include "harness/ranking.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace atmos {

std::vector<int> TiedRanks(const std::vector<double>& values, double noise) {
    const double tolerance = noise > 0.0 ? noise : 0.0;
    std::vector<int> order;
    for (size_t i = 0; i < values.size(); ++i) {
        if (std::isfinite(values[i])) order.push_back(static_cast<int>(i));
    }
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return values[a] < values[b]; });
    std::vector<int> ranks(values.size(), 0);
    size_t i = 0;
    while (i < order.size()) {
        const double leader = values[order[i]];
        const int rank = static_cast<int>(i) + 1;
        size_t j = i;
        while (j < order.size() && values[order[j]] - leader <= tolerance) {
            ranks[order[j]] = rank;
            ++j;
        }
        i = j;
    }
    return ranks;
}

std::vector<int> BestOfRow(const std::vector<double>& values, double noise) {
    const std::vector<int> ranks = TiedRanks(values, noise);
    std::vector<int> best;
    for (size_t i = 0; i < ranks.size(); ++i) {
        if (ranks[i] == 1) best.push_back(static_cast<int>(i));
    }
    return best;
}

std::vector<int> ParetoFront(const std::vector<double>& cost, const std::vector<double>& error) {
    std::vector<int> order;
    for (size_t i = 0; i < cost.size() && i < error.size(); ++i) {
        if (std::isfinite(cost[i]) && std::isfinite(error[i])) order.push_back(static_cast<int>(i));
    }
    // By cost, then error: a point is on the front when its error is below
    // every error of the cheaper (or equally cheap, listed earlier) points.
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return cost[a] < cost[b] || (cost[a] == cost[b] && error[a] < error[b]);
    });
    std::vector<int> front;
    double best_error = INFINITY;
    for (int i : order) {
        if (error[i] < best_error) {
            front.push_back(i);
            best_error = error[i];
        }
    }
    return front;
}

}  // namespace atmos
