// atmos: precomputed multiple-scattering orders that stop decreasing (issue 18
// item 4).
//
// Each scattering order's radiance is at most the single-scattering albedo
// w <= 1 times the previous order's: the source of order k + 1 is w times a
// phase-weighted mean of order k, and a view ray transmits at most all of it
// (sup L_{k+1} <= w sup L_k). The orders of an energy-conserving method
// therefore decrease. A precomputation whose order k carries as much as order
// k - 1 (summed over its table, an energy proxy) gains energy in its gather or
// density integral: for that atmosphere (optically thick or strongly forward
// scattering) the method is past its limit and its radiance is not valid. The
// models record each order's sum and, when the orders stop decreasing, say so
// on stderr (and the model's `atmos list` validity says where this happens).
#pragma once

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "base/texture.h"

namespace atmos {

// Sum of every value of a table (host memory).
inline double TableSum(const Table& table) {
    const TableView& v = table.view();
    double sum = 0.0;
    const size_t n =
        static_cast<size_t>(v.width) * v.height * v.depth * static_cast<size_t>(v.channels);
    for (size_t i = 0; i < n; ++i) sum += static_cast<double>(v.data[i]);
    return sum;
}

// Largest value of a table (host memory; 0 for an empty one).
inline double TableMax(const Table& table) {
    const TableView& v = table.view();
    double m = 0.0;
    const size_t n =
        static_cast<size_t>(v.width) * v.height * v.depth * static_cast<size_t>(v.channels);
    for (size_t i = 0; i < n; ++i) m = std::max(m, static_cast<double>(v.data[i]));
    return m;
}

// Hillaire's multiple scattering (hillaire.h, paper Eq. 5-10) sums every order
// beyond the second as a geometric series L_2nd (f_ms + f_ms^2 + ...): it
// assumes each order is re-scattered with the transfer f_ms of the second
// (isotropic, and the neighbourhood lit as the point). Where f_ms exceeds
// kSeriesTransferLimit, the orders the series assumes (f_ms / (1 - f_ms) times
// the second) carry more than the second order it computes: the result rests
// on the assumption, which over-brightens optically thick media (the path
// tracer's light decays with depth, the series' does not).
constexpr double kSeriesTransferLimit = 0.5;

// Prints one warning line on stderr when the largest transfer f_ms exceeds
// kSeriesTransferLimit; returns whether it did.
inline bool WarnIfSeriesPastLimit(const char* model, double max_transfer) {
    if (!(max_transfer > kSeriesTransferLimit)) return false;
    std::fprintf(stderr,
                 "atmos: warning: model %s: multiple-scattering transfer f_ms reaches %.3g (above "
                 "%.2g: the orders its series 1 / (1 - f_ms) assumes outweigh the second order it "
                 "computes): optically thick atmosphere, its radiance is not valid here (`atmos "
                 "list %s`, validity)\n",
                 model, max_transfer, kSeriesTransferLimit, model);
    return true;
}

class ScatteringOrders {
  public:
    // `order`'s table sum, in increasing order; orders before first_compared
    // are recorded but not compared (their tables may hold other units).
    void Add(int order, double sum) {
        orders_.push_back(order);
        sums_.push_back(sum);
    }
    // The first order at least as large as its predecessor (0: they decrease),
    // comparing orders >= first_compared; *ratio receives its ratio.
    int FirstNotDecreasing(int first_compared, double* ratio) const {
        for (size_t i = 1; i < sums_.size(); ++i) {
            if (orders_[i] < first_compared || orders_[i - 1] < first_compared - 1) continue;
            const double prev = sums_[i - 1];
            const double r = prev > 0.0 ? sums_[i] / prev : (sums_[i] > 0.0 ? 1e300 : 0.0);
            if (!(r < 1.0)) {
                if (ratio) *ratio = r;
                return orders_[i];
            }
        }
        return 0;
    }
    // Prints one warning line on stderr when the orders stop decreasing;
    // returns whether it did.
    bool WarnIfDiverging(const char* model, int first_compared) const {
        double ratio = 0.0;
        const int k = FirstNotDecreasing(first_compared, &ratio);
        if (k == 0) return false;
        std::fprintf(stderr,
                     "atmos: warning: model %s: scattering order %d carries %.3g times the energy "
                     "of order %d (orders must decrease): its precomputed multiple scattering "
                     "diverges for this atmosphere (optically thick or strongly forward "
                     "scattering) and its radiance is not valid here (`atmos list %s`, validity)\n",
                     model, k, ratio, k - 1, model);
        return true;
    }

  private:
    std::vector<int> orders_;
    std::vector<double> sums_;
};

}  // namespace atmos
