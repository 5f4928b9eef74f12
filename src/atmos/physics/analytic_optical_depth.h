// atmos: closed-form and fitted approximations of the optical length of an
// exponential atmosphere, and the constant-density ozone shell.
//
// "Optical length" here is the integral of a dimensionless density along a ray,
// in metres (density 1 at the ground); multiplying by a coefficient (1/m) gives
// an optical depth. Every approximation gives the optical length from a point
// at radius r, direction cosine mu, to infinity along the ray ("ToInfinity");
// segments are built from those by differences (SegmentFromToInfinity below).
//
// Sources:
//   flat / homogeneous sphere   Leenman's 2025 thesis section 10.2, Eq. 50-51 (looking up),
//                               section 10.3, Eq. 53 (looking down)
//   Chapman (Schuler 2012)      Leenman's 2025 thesis section 5.1, Eq. 22-25
//   erfc (Bruneton & Neyret 08) Leenman's 2025 thesis section 5.1, Eq. 26-30 and Listing 3
//   O'Neil 2005 scale()         Raush's O'Neil slides (2018) (vertex shader "scale"), Leenman's
//   2025 thesis Eq. 17 ozone shell                 Leenman's 2025 thesis section 10.5, Eq. 59
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "physics/geometry.h"

namespace atmos {

// Largest optical length (m) any approximation returns: keeps exp(-beta l) = 0
// without infinities or inf - inf in the differences below.
constexpr double kMaxOpticalLength = 1e12;

ATMOS_HD inline double ClampLength(double l) { return Clamp(l, 0.0, kMaxOpticalLength); }

// exp(x) with x clamped to [-700, 60]: the densities below ground that the
// "looking down" forms evaluate at the tangent point stay finite.
ATMOS_HD inline double SafeExp(double x) { return Exp(Clamp(x, -700.0, 60.0)); }

// ---------------------------------------------------------------------------
// Flat / homogeneous sphere (Leenman's 2025 thesis section 10.2-10.3).

// Eq. 51: density at the point times the length of the ray (r, mu) inside the
// homogeneous sphere of radius r + H: exp(-h/H) (sqrt((r+H)^2 - r^2 + r^2 mu^2) - r mu).
// The bracket is Eq. 50 written for a viewer at radius r. Valid for mu >= 0.
ATMOS_HD inline double FlatLengthUp(double r, double mu, double scale_height, double bottom) {
    const double H = scale_height;
    const double chord = SafeSqrt(H * (2.0 * r + H) + r * r * mu * mu) - r * mu;
    return ClampLength(SafeExp(-(r - bottom) / H) * chord);
}

// Eq. 53 for mu < 0 ("looking down"): twice the horizontal length at the ray's
// point closest to the centre c, minus the part behind the viewer (Eq. 51 with
// -mu). Deviation: Eq. 53 as printed uses the viewer's radius for the tangent
// term and no densities; here each term carries the density at its own point
// (exp(-h_c/H) at the tangent point, as Schuler's Eq. 23 does), so a viewer at
// any altitude gets the right scale and a ray through the planet a huge length.
ATMOS_HD inline double FlatLengthToInfinity(double r, double mu, double scale_height,
                                            double bottom) {
    if (mu >= 0.0) return FlatLengthUp(r, mu, scale_height, bottom);
    const double r_c = r * SafeSqrt(1.0 - mu * mu);
    return ClampLength(2.0 * FlatLengthUp(r_c, 0.0, scale_height, bottom) -
                       FlatLengthUp(r, -mu, scale_height, bottom));
}

// ---------------------------------------------------------------------------
// Chapman function approximation of Schuler 2012 (Leenman's 2025 thesis Eq. 24-25).

// Optical length (m) from (r, mu) to infinity for density exp(-(r' - bottom)/H):
//   mu >= 0: H exp(-h/H) c / (1 + c mu),                       c = sqrt(r / (u H))
//   mu <  0: 2 H sqrt(x0) exp((bottom - r_c)/H) - H exp(-h/H) c / (1 - c mu),
//            x0 = sqrt(1 - mu^2) r / (u H) = r_c / (u H)
// (Eq. 24-25 with x = (R+h)/H; the complement is Eq. 23: the full line through
// the tangent point minus the part behind the viewer.) The seed prints Eq. 25
// with the scale height as the unit (u = 1): then Ch(x, 90 deg) = sqrt(x)
// against the exact asymptote sqrt(pi x / 2), 20% low. Schuler's own code
// measures X and h in units of the 50%-height H ln 2 (exp2 instead of exp):
// u = ln 2 gives Ch(x, 90 deg) = sqrt(x / ln 2), 4.2% low. Errors of both:
// tests/analytic_test.cpp (Chapman.*) and docs/models/analytic.md.
constexpr double kChapmanSeedUnit = 1.0;
constexpr double kChapmanHalfHeightUnit = 0.69314718055994531;  // ln 2
ATMOS_HD inline double ChapmanLengthToInfinity(double r, double mu, double scale_height,
                                               double bottom, double unit = kChapmanSeedUnit) {
    const double H = scale_height;
    const double c = Sqrt(r / (unit * H));
    const double density = SafeExp(-(r - bottom) / H);
    if (mu >= 0.0) return ClampLength(H * density * c / (1.0 + c * mu));
    const double r_c = SafeSqrt(1.0 - mu * mu) * r;
    const double tangent = 2.0 * H * Sqrt(r_c / (unit * H)) * SafeExp((bottom - r_c) / H);
    return ClampLength(tangent - H * density * c / (1.0 - c * mu));
}

// ---------------------------------------------------------------------------
// Bruneton & Neyret 2008's erfc approximation (Leenman's 2025 thesis Eq. 27-30, Listing 3).

// Eq. 30 in the scaled form used by Listing 3: exp(x^2) erfc(x) / 2 for x >= 0,
// 1 / (2.3193 x + sqrt(1.52 x^2 + 4)).
ATMOS_HD inline double ScaledErfcHalf(double x) {
    return 1.0 / (2.3193 * x + Sqrt(1.52 * x * x + 4.0));
}

// Optical length (m) of density exp(-(r' - bottom)/H) along the segment of
// length d from (r, mu). With sqrt(1+u) ~ 1 + u/2 (Eq. 27) the altitude along
// the ray is h + t mu + t^2/(2r), and the integral (Eq. 28) is
//   exp(-h/H) sqrt(2 pi r H) / 2 [E(a0) - exp(a0^2 - a1^2) E(a1)],
//   E(a) = exp(a^2) erfc(a), a0 = mu sqrt(r/(2H)), a1 = (mu + d/r) sqrt(r/(2H)),
// a0^2 - a1^2 = -(d/H)(mu + d/(2r)); erfc(-x) = 2 - erfc(x) for negative
// arguments (the 2 survives only when a0 < 0 <= a1: the segment crosses the
// tangent point). Listing 3 written out with these names.
ATMOS_HD inline double ErfcSegmentLength(double r, double mu, double d, double scale_height,
                                         double bottom) {
    const double H = scale_height;
    const double a = Sqrt(0.5 * r / H);
    const double a0 = a * mu;
    const double a1 = a * (mu + d / r);
    const double s0 = a0 < 0.0 ? -1.0 : 1.0;
    const double s1 = a1 < 0.0 ? -1.0 : 1.0;
    const double h_over_H = (r - bottom) / H;
    // exp(-h/H) exp(a0^2) erfc(a0) / 2 and exp(-h/H) exp(a0^2) erfc(a1) / 2 with
    // the sign rule; exponents are summed before exp() so that no factor
    // overflows on its own (exp(a0^2 - h/H) is the density at the tangent point).
    const double cross = (s1 > s0) ? SafeExp(a0 * a0 - h_over_H) : 0.0;
    const double y0 = s0 * ScaledErfcHalf(Abs(a0)) * SafeExp(-h_over_H);
    const double y1 =
        s1 * ScaledErfcHalf(Abs(a1)) * SafeExp(-h_over_H - (d / H) * (mu + d / (2.0 * r)));
    const double value = Sqrt(2.0 * kPi * H * r) * (cross + y0 - y1);
    return ClampLength(value);
}

// ---------------------------------------------------------------------------
// O'Neil 2005 (GPU Gems 2 ch. 16; Raush's O'Neil slides (2018) "scale"; Leenman's 2025 thesis Eq.
// 17).

// The fitted optical length of O'Neil's scale(): in units of the atmosphere's
// thickness L = top - bottom, from a point at normalised altitude h/L looking
// along a direction with cosine mu to infinity,
//   exp(-h / H) * (H / L) * exp(p(1 - mu)),  p(x) = c0 + c1 x + ... + c4 x^4.
// Original constants (atmosphere 2.5% of the planet radius, H/L = 0.25):
// c = (-0.00287, 0.459, 3.83, -6.80, 5.25).
struct OneilScale {
    double c[5] = {-0.00287, 0.459, 3.83, -6.80, 5.25};
    double scale_height = 0.0;  // H (m)
    double thickness = 0.0;     // L (m)

    ATMOS_HD double Polynomial(double x) const {
        return c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * c[4])));
    }
    // O'Neil's scale(cos): (H/L) exp(p(1 - cos)), dimensionless.
    ATMOS_HD double Scale(double mu) const {
        return (scale_height / thickness) * SafeExp(Polynomial(1.0 - mu));
    }
    // Optical length (m) to infinity from radius r along mu: L exp(-h/H) scale(mu).
    // O'Neil's shaders also call scale() with mu < 0 (the polynomial
    // extrapolated beyond x = 1); so does this.
    ATMOS_HD double LengthToInfinity(double r, double mu, double bottom) const {
        return ClampLength(thickness * SafeExp(-(r - bottom) / scale_height) * Scale(mu));
    }
};

// ---------------------------------------------------------------------------
// Segments from "to infinity" functions.

// Optical length along the segment from `p0` (radius r0, cosine mu0) a
// distance `d` along the ray, built from a function f(r, mu) >= 0 evaluated
// only for mu >= 0 (where the approximations are valid) by differences:
//   ray going up at both ends:   f(p0, mu0) - f(p1, mu1)
//   ray going down at both ends: f(p1, -mu1) - f(p0, -mu0)   (reversed ray;
//                                Bruneton & Neyret 2008's trick, Leenman's 2025 thesis s. 11.3.3)
//   down then up (crosses the tangent point c): 2 f(c, 0) - f(p0, -mu0) - f(p1, mu1)
//                                (Eq. 53's decomposition)
template <typename F>
ATMOS_HD inline double SegmentFromToInfinity(const F& f, double r0, double mu0, double d) {
    const double r1 = SafeSqrt(d * d + 2.0 * r0 * mu0 * d + r0 * r0);
    const double mu1 = ClampCosine((r0 * mu0 + d) / Max(r1, 1e-9));
    double l;
    if (mu0 >= 0.0) {
        l = f(r0, mu0) - f(r1, mu1);
    } else if (mu1 <= 0.0) {
        l = f(r1, -mu1) - f(r0, -mu0);
    } else {
        const double r_c = r0 * SafeSqrt(1.0 - mu0 * mu0);
        l = 2.0 * f(r_c, 0.0) - f(r0, -mu0) - f(r1, mu1);
    }
    return ClampLength(l);
}

// The segment [t0, t1] of the ray origin + t dir as SegmentFromToInfinity
// takes it: the radius r and view cosine mu at its start, and its length d.
struct RaySegmentStart {
    double r, mu, d;
};
ATMOS_HD inline RaySegmentStart RaySegmentStartOf(const Vec3d& origin, const Vec3d& dir, double t0,
                                                  double t1) {
    const Vec3d p = origin + dir * t0;
    const double r = Length(p);
    return {r, ClampCosine(Dot(p, dir) / r), Max(t1 - t0, 0.0)};
}

// The optical depth of the segment [t0, t1] of the ray origin + t dir through
// Rayleigh (scattering coefficient at the ground) and Mie (extinction), from
// each medium's length to infinity (`rayleigh`, `mie`: functions as above).
template <typename F>
ATMOS_HD inline Vec3d RayleighMieSegmentDepth(const Vec3d& rayleigh_scattering, const F& rayleigh,
                                              const Vec3d& mie_extinction, const F& mie,
                                              const Vec3d& origin, const Vec3d& dir, double t0,
                                              double t1) {
    const auto [r, mu, d] = RaySegmentStartOf(origin, dir, t0, t1);
    return rayleigh_scattering * SegmentFromToInfinity(rayleigh, r, mu, d) +
           mie_extinction * SegmentFromToInfinity(mie, r, mu, d);
}

// ---------------------------------------------------------------------------
// Ozone as a constant-density shell (Leenman's 2025 thesis section 10.5, Eq. 59).

struct OzoneShell {
    double r_inner = 0.0;  // m from the centre
    double r_outer = 0.0;  // r_outer <= r_inner: no shell
    ATMOS_HD bool Empty() const { return r_outer <= r_inner; }
};

// The shell that has the absorption profile's column (integral of the density
// over altitude) and centroid: [centroid - column/2, centroid + column/2].
// For `earth`'s tent (0 at 10 km, 1 at 25 km, 0 at 40 km) this is exactly
// Eq. 59's 17.5-32.5 km. Host only (numerical integration).
OzoneShell MakeOzoneShell(const AtmosphereParameters& atm);

// Length of the part of the segment [t0, t1] of the ray origin + t dir that
// lies inside the sphere of radius `radius`.
ATMOS_HD inline double LengthInsideSphere(const Vec3d& origin, const Vec3d& dir, double t0,
                                          double t1, double radius) {
    double a, b;
    if (!IntersectSphere(origin, dir, radius, &a, &b)) return 0.0;
    return Max(0.0, Min(b, t1) - Max(a, t0));
}

// Length of [t0, t1] inside the shell: the chord of the outer sphere minus the
// chord of the inner one (exact).
ATMOS_HD inline double ShellLength(const OzoneShell& shell, const Vec3d& origin, const Vec3d& dir,
                                   double t0, double t1) {
    if (shell.Empty()) return 0.0;
    return Max(0.0, LengthInsideSphere(origin, dir, t0, t1, shell.r_outer) -
                        LengthInsideSphere(origin, dir, t0, t1, shell.r_inner));
}

// ---------------------------------------------------------------------------
// Mapping our layered profiles to the single scale height these models need.

// The scale height H of a profile whose upper layer (the one every profile of
// the presets uses above the ground) is exp_term * exp(-h / H): -1/exp_scale.
// Returns `fallback` for a profile that is not a decaying exponential.
inline double ProfileScaleHeight(const DensityProfile& profile, double fallback) {
    const DensityProfileLayer& layer = profile.layers[1];
    if (layer.exp_term > 0.0 && layer.exp_scale < 0.0) return -1.0 / layer.exp_scale;
    return fallback;
}

// The ratio of the single-exponential approximation to the true profile is 1
// for profiles made by ExponentialProfile; a profile with a multiplier
// (exp_term != 1) keeps it here.
inline double ProfileExpTerm(const DensityProfile& profile) {
    const DensityProfileLayer& layer = profile.layers[1];
    return layer.exp_term > 0.0 && layer.exp_scale < 0.0 ? layer.exp_term : 0.0;
}

}  // namespace atmos
