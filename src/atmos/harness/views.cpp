// atmos: the 12 views of Leenman's 2025 thesis section 11.4 (numbers in docs/views.md).
#include <cmath>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/view.h"

namespace atmos {

Camera MakeCamera(const Vec3d& position, const Vec3d& forward, const Vec3d& world_up,
                  double vfov_deg) {
    Camera c;
    c.position = position;
    c.forward = Normalize(forward);
    c.right = Normalize(Cross(c.forward, world_up));
    c.up = Cross(c.right, c.forward);
    c.tan_half_fov_y = std::tan(Radians(vfov_deg) * 0.5);
    return c;
}

namespace {

// Unit vector at azimuth `azimuth_deg` (from +x toward +y) and elevation
// `elevation_deg` above the plane z = 0.
Vec3d AzimuthElevation(double azimuth_deg, double elevation_deg) {
    const double a = Radians(azimuth_deg);
    const double e = Radians(elevation_deg);
    return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

std::string SunDescription(double elevation_deg) {
    if (elevation_deg >= 90.0) return "sun overhead";
    return std::string("sun toward the viewer, 6 deg ") +
           (elevation_deg < 0.0 ? "below" : "above") + " the horizon";
}

constexpr double kViewVfovDeg = 60.0;    // ground, plane, orbit and planet-shadow views
constexpr double kSpaceVfovDeg = 40.0;   // the whole planet
constexpr double kSkyPitchDeg = 10.0;    // ground and plane: horizon a third below the centre
constexpr double kOrbitBackM = 1000e3;   // orbit: 100 km up, then 1000 km back
constexpr double kShadowYawDeg = 150.0;  // planet shadow: looking 150 deg away from the sun
constexpr double kShadowOrbitPitchDeg = -12.0;
constexpr double kSpaceDistanceFactor = 3.75;  // space: camera at 3.75 top radii

}  // namespace

std::vector<View> StandardViews(const AtmosphereParameters& atmosphere) {
    const double R = atmosphere.bottom_radius;
    const Vec3d z(0.0, 0.0, 1.0);
    std::vector<View> views;

    struct TimeOfDay {
        const char* name;
        double sun_elevation_deg;
        float exposure;
    };
    const TimeOfDay times[] = {{"dawn", -6.0, 16.0f}, {"sunrise", 6.0, 1.0f}, {"noon", 90.0, 1.0f}};

    // Ground and plane: looking horizontally toward the sun's azimuth (+x),
    // pitched up so that the horizon sits a third of the way up the image.
    struct Place {
        const char* name;
        double altitude;
    };
    const Place places[] = {{"ground", 0.0}, {"plane", 5000.0}};
    for (const Place& place : places) {
        for (const TimeOfDay& t : times) {
            View v;
            v.name = std::string(place.name) + "-" + t.name;
            v.description = std::string(place.altitude == 0.0 ? "on the ground" : "at 5 km") +
                            ", " + SunDescription(t.sun_elevation_deg);
            v.camera = MakeCamera(Vec3d(0.0, 0.0, R + place.altitude),
                                  AzimuthElevation(0.0, kSkyPitchDeg), z, kViewVfovDeg);
            v.sun_direction = AzimuthElevation(0.0, t.sun_elevation_deg);
            v.exposure = t.exposure;
            views.push_back(v);
        }
    }
    // Orbit: 100 km above the reference point, then 1000 km back, looking
    // horizontally (in the reference frame) toward the sun: the limb.
    for (const TimeOfDay& t : times) {
        View v;
        v.name = std::string("orbit-") + t.name;
        v.description = "100 km up and 1000 km back, looking at the limb; " +
                        SunDescription(t.sun_elevation_deg);
        v.camera =
            MakeCamera(Vec3d(-kOrbitBackM, 0.0, R + 100e3), Vec3d(1.0, 0.0, 0.0), z, kViewVfovDeg);
        v.sun_direction = AzimuthElevation(0.0, t.sun_elevation_deg);
        v.exposure = t.exposure;
        views.push_back(v);
    }
    {
        // Space: the whole planet from 3.75 top radii, sun to the top right and
        // slightly toward the camera, so lit and dark sides both show.
        View v;
        v.name = "space";
        v.description = "the whole planet from space, sun to the top right";
        const double distance = kSpaceDistanceFactor * atmosphere.top_radius;
        v.camera = MakeCamera(Vec3d(0.0, -distance, 0.0), Vec3d(0.0, 1.0, 0.0), z, kSpaceVfovDeg);
        v.sun_direction = Normalize(Vec3d(0.8, -0.3, 0.5));
        v.exposure = 2.0f;
        views.push_back(v);
    }
    {
        // Planet shadow: sun 3 deg below the horizon at azimuth 0, on the right
        // of a camera that looks 150 deg away from it, so the antisolar point
        // (where the planet's shadow rises) is 30 deg left of the image centre.
        View ground;
        ground.name = "planet-shadow-ground";
        ground.description = "on the ground, sun 3 deg below the horizon to the right (behind)";
        ground.camera = MakeCamera(Vec3d(0.0, 0.0, R),
                                   AzimuthElevation(kShadowYawDeg, kSkyPitchDeg), z, kViewVfovDeg);
        ground.sun_direction = AzimuthElevation(0.0, -3.0);
        ground.exposure = 32.0f;
        views.push_back(ground);

        View orbit = ground;
        orbit.name = "planet-shadow-orbit";
        orbit.description = "200 km up, sun 3 deg below the horizon to the right (behind)";
        orbit.camera =
            MakeCamera(Vec3d(0.0, 0.0, R + 200e3),
                       AzimuthElevation(kShadowYawDeg, kShadowOrbitPitchDeg), z, kViewVfovDeg);
        views.push_back(orbit);
    }
    return views;
}

std::vector<std::string> StandardViewNames() {
    std::vector<std::string> names;
    for (const View& v : StandardViews(AtmosphereParameters{})) names.push_back(v.name);
    return names;
}

View GetView(const std::string& name, const AtmosphereParameters& atmosphere) {
    for (const View& v : StandardViews(atmosphere)) {
        if (v.name == name) return v;
    }
    std::string list;
    for (const std::string& n : StandardViewNames()) list += (list.empty() ? "" : ", ") + n;
    Fail("unknown view '", name, "' (views: ", list, ")");
}

}  // namespace atmos
