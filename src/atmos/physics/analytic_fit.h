// atmos: host-side least-squares fits of the analytic models (O'Neil's scale()
// polynomial, Raush's O'Neil slides (2018) / Leenman's 2025 thesis Eq. 17) and the numerical
// optical lengths they are fitted to.
#pragma once

#include "physics/analytic_optical_depth.h"

namespace atmos {

// Optical length (m) of density exp(-(r' - bottom)/H) from (r, mu) to the top
// of the atmosphere (radius `top`), midpoint rule with `samples` steps. The ray
// must not hit the ground (mu >= 0 always qualifies).
double NumericalExpLength(double r, double mu, double H, double bottom, double top,
                          int samples = 2000);

// Solves the n x n system A x = b (row-major A) by Gaussian elimination with
// partial pivoting; b is replaced by x. Returns false for a singular system.
bool SolveLinearSystem(int n, double* a, double* b);

// Refit of O'Neil's scale() polynomial (OneilScale::c) for one exponential
// medium of scale height H in the atmosphere [bottom, top]: fits
// log(l(h, mu) / (H exp(-h/H))) = p(1 - mu) over mu in [0, 1] (64 values) and
// altitudes h in {0, H/4, H/2, H, 2H} (those below half the thickness), l the
// numerical optical length to the top (NumericalExpLength): least squares,
// then Lawson's iteratively reweighted least squares toward the minimax fit
// (the best maximum error is kept).
OneilScale FitOneilScale(double H, double bottom, double top);

// O'Neil's original constants, for a medium of scale height H in [bottom, top].
OneilScale OriginalOneilScale(double H, double bottom, double top);

// Largest relative error of `scale` against the numerical optical length over
// mu in [mu_min, 1] (256 values) at altitude h.
double OneilScaleMaxRelativeError(const OneilScale& scale, double h, double bottom, double top,
                                  double mu_min = 0.0);

}  // namespace atmos
