// atmos: ray / sphere geometry of a spherical planet, in double precision.
//
// Source: Bruneton 2017, functions.glsl "Intersections":
// DistanceToTopAtmosphereBoundary, DistanceToBottomAtmosphereBoundary,
// RayIntersectsGround, extended with a general ray / sphere intersection for
// cameras anywhere (including space) that uses the numerically stable form of
// the quadratic (Press et al., Numerical Recipes 5.6), so grazing rays and
// cameras at 6.4e6 m keep their precision.
//
// Conventions: the planet's centre is the origin; r is a distance to the centre,
// mu the cosine of the angle between a direction and the local zenith.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"

namespace atmos {

// Distance from (r, mu) to the sphere of radius `top` along the ray, for a point
// inside it (r <= top). Bruneton's 2017 implementation notes: -r mu + sqrt(r^2 (mu^2 - 1) + top^2).
ATMOS_HD inline double DistanceToTopAtmosphereBoundary(double r, double mu, double top) {
    ATMOS_DASSERT(mu >= -1.0 && mu <= 1.0);
    const double discriminant = r * r * (mu * mu - 1.0) + top * top;
    return Max(-r * mu + SafeSqrt(discriminant), 0.0);
}

// Distance from (r, mu) to the ground sphere of radius `bottom` (nearest hit),
// for a ray that intersects it. Bruneton's 2017 implementation notes: -r mu - sqrt(r^2 (mu^2 - 1) +
// bottom^2).
ATMOS_HD inline double DistanceToBottomAtmosphereBoundary(double r, double mu, double bottom) {
    ATMOS_DASSERT(mu >= -1.0 && mu <= 1.0);
    const double discriminant = r * r * (mu * mu - 1.0) + bottom * bottom;
    return Max(-r * mu - SafeSqrt(discriminant), 0.0);
}

// True when the ray (r, mu) with r >= bottom hits the ground sphere. Bruneton's 2017 implementation
// notes: mu < 0 and r^2 (mu^2 - 1) + bottom^2 >= 0. The discriminant is evaluated as bottom^2 - r^2
// (1 - mu^2) = (bottom - r)(bottom + r) + (r mu)^2 so that a camera on the ground (r == bottom)
// looking just below the horizon is exact.
ATMOS_HD inline bool RayIntersectsGround(double r, double mu, double bottom) {
    ATMOS_DASSERT(mu >= -1.0 && mu <= 1.0);
    return mu < 0.0 && (bottom - r) * (bottom + r) + (r * mu) * (r * mu) >= 0.0;
}

// Intersections t0 <= t1 of the ray origin + t dir (|dir| = 1) with the sphere of
// radius `radius` centred at the origin. Returns false when the ray's line
// misses the sphere. t0 may be negative (origin inside, or sphere behind).
ATMOS_HD inline bool IntersectSphere(const Vec3d& origin, const Vec3d& dir, double radius,
                                     double* t0, double* t1) {
    const double b = Dot(origin, dir);  // half the linear coefficient
    const double r = Length(origin);
    const double c = (r - radius) * (r + radius);  // |o|^2 - R^2 without cancellation
    const double discriminant = b * b - c;
    if (discriminant < 0.0) return false;
    const double s = Sqrt(discriminant);
    // Stable roots: q = -(b + sign(b) s); roots q and c / q.
    const double q = -(b + (b >= 0.0 ? s : -s));
    double ta = q;
    double tb = (q != 0.0) ? c / q : -b;
    if (ta > tb) {
        const double tmp = ta;
        ta = tb;
        tb = tmp;
    }
    *t0 = ta;
    *t1 = tb;
    return true;
}

// The part of a view ray that lies inside the atmosphere, and what ends it.
struct AtmosphereSegment {
    bool inside = false;       // the ray crosses the atmosphere at all (t_end > t_start)
    bool hits_ground = false;  // the segment ends on the ground
    double t_start = 0.0;      // m: where the ray enters (0 for a camera inside)
    double t_end = 0.0;        // m: where it leaves the top or meets the ground
};

// Clips the ray camera + t dir (t >= 0, |dir| = 1) against the atmosphere shell.
// A camera in space starts where the ray enters the top sphere; a camera below
// the ground (never used by the views) is treated as on the ground.
ATMOS_HD inline AtmosphereSegment ClipToAtmosphere(const Vec3d& camera, const Vec3d& dir,
                                                   double bottom, double top) {
    AtmosphereSegment seg;
    double top0 = 0.0, top1 = 0.0;  // set by IntersectSphere when it hits (GCC -O3 cannot tell)
    if (!IntersectSphere(camera, dir, top, &top0, &top1) || top1 <= 0.0) return seg;
    seg.t_start = Max(top0, 0.0);
    seg.t_end = top1;
    const double r = Length(camera);
    if (r <= bottom) {
        // On (or numerically below) the ground: the ground blocks everything
        // below the horizon; the local horizon is the plane through the camera.
        const double mu = Dot(camera, dir) / r;
        if (mu < 0.0) {
            seg.hits_ground = true;
            seg.t_end = 0.0;
            return seg;
        }
    } else {
        double g0, g1;
        if (IntersectSphere(camera, dir, bottom, &g0, &g1) && g0 > 0.0 && g0 < seg.t_end) {
            seg.hits_ground = true;
            seg.t_end = g0;
        }
    }
    seg.inside = seg.t_end > seg.t_start;
    return seg;
}

}  // namespace atmos
