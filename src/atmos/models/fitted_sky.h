// atmos: what the fitted ground-viewer skies (`preetham`, `hosek-wilkie`)
// share: their capabilities, the sun raised to the horizon, the sun terms of the view kept by
// PrepareView (physics/ray.h), and their Evaluate around the sky's formula.
#pragma once

#include "atmos/math.h"
#include "atmos/model.h"
#include "physics/geometry.h"
#include "physics/ray.h"

namespace atmos {

// The capabilities both share: a ground viewer's sky (no space views, no sun
// below the horizon), no transmittance, fitted to a full simulation (multiple
// scattering).
inline ModelCapabilities FittedSkyCapabilities() {
    ModelCapabilities c;
    c.transmittance = false;
    c.space_views = false;
    c.sun_below_horizon = false;
    c.multiple_scattering = true;
    return c;
}

// Their validity domain: a sky fitted to `name`'s (`fit`'s) radii, density
// profiles and Mie asymmetry (ValidityDomain::fitted_to); Prepare() warns on
// another atmosphere.
inline ValidityDomain FittedSkyDomain(const std::string& name, const AtmosphereParameters& fit) {
    ValidityDomain d;
    d.fitted_to = name;
    d.fitted_atmosphere = std::make_shared<const AtmosphereParameters>(fit);
    return d;
}
inline ValidityDomain FittedToEarthDomain() {
    static const ValidityDomain earth = FittedSkyDomain("earth", EarthAtmosphere());
    return earth;
}

// The sun direction, raised to the horizon of `up` when below it; *cos_s is
// its cosine to `up` (0 when raised).
ATMOS_HD inline Vec3d SunRaisedToHorizon(const Vec3d& up, const Vec3d& sun, double* cos_s) {
    *cos_s = Dot(sun, up);
    if (!(*cos_s < 0.0)) return sun;
    const Vec3d horizontal = sun - up * *cos_s;
    const double len = Length(horizontal);
    *cos_s = 0.0;
    return len > 1e-9 ? horizontal / len : Normalize(Cross(up, Vec3d(1.0, 0.0, 0.0)));
}

// The sun terms of the view set by PrepareView (render/render.h calls it once
// per frame): a ray from that camera toward that sun reuses them; any other
// (a sample query) computes its own, by the same code.
template <typename Terms>
struct FittedSkyView {
    bool has_view = false;
    Vec3d camera, sun;
    Terms terms;

    ATMOS_HD void Set(const Vec3d& view_camera, const Vec3d& view_sun, const Terms& t) {
        terms = t;
        camera = view_camera;
        sun = view_sun;
        has_view = true;
    }
    ATMOS_HD bool Matches(const Vec3d& c, const Vec3d& s) const {
        return has_view && c.x == camera.x && c.y == camera.y && c.z == camera.z && s.x == sun.x &&
               s.y == sun.y && s.z == sun.z;
    }
};

// The evaluator of a fitted sky (CRTP, no virtual call). Derived provides
//   ATMOS_HD Terms SunTerms(const Vec3d& up, const Vec3d& sun) const;
//   ATMOS_HD Rgb Sky(const Terms& st, const Vec3d& up, const Vec3d& dir) const;
// (the terms that depend on the sun and the camera's up only, and the sky's
// radiance toward `dir`). A ray that hits the ground or misses the atmosphere
// gets no sky; T is 1 (0 toward the ground): the fitted skies have no
// transmittance and no ground term.
template <typename Derived, typename Terms>
struct FittedSkyEvaluator {
    double bottom = 6360e3, top = 6460e3;
    FittedSkyView<Terms> view;  // PrepareView's

    ATMOS_HD void PrepareView(const Vec3d& camera, const Vec3d& sun) {
        view.Set(camera, sun, Self().SunTerms(Normalize(camera), sun));
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool) const {
        RayResult out;
        out.transmittance = Rgb(1.0f);
        const AtmosphereSegment seg = ClipToAtmosphere(camera, dir, bottom, top);
        out.hits_ground = seg.hits_ground;
        if (seg.hits_ground) out.transmittance = Rgb(0.0f);
        if (!seg.inside || seg.hits_ground) return out;
        const Vec3d up = Normalize(camera);
        const Terms st = view.Matches(camera, sun) ? view.terms : Self().SunTerms(up, sun);
        out.sky = Self().Sky(st, up, dir);
        return out;
    }

  private:
    ATMOS_HD const Derived& Self() const { return static_cast<const Derived&>(*this); }
};

}  // namespace atmos
