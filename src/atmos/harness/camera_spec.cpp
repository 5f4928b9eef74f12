// atmos: free cameras and suns (`--camera`, `--sun`; conventions in docs/views.md).
#include <cmath>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "atmos/error.h"
#include "atmos/number.h"
#include "atmos/sun_position.h"
#include "atmos/view.h"

namespace atmos {

namespace {

// "KEY=VALUE[,KEY=VALUE...]" as (key, value) pairs in order; `flag` names the
// option in messages.
std::vector<std::pair<std::string, std::string>> SplitKeyValues(const std::string& text,
                                                                const char* flag,
                                                                const char* form) {
    std::vector<std::pair<std::string, std::string>> out;
    if (text.empty()) Fail(flag, " is empty: expected ", form);
    size_t begin = 0;
    for (;;) {
        const size_t comma = text.find(',', begin);
        const std::string item = text.substr(begin, comma - begin);
        const size_t eq = item.find('=');
        if (eq == std::string::npos || eq == 0) {
            Fail(flag, ": '", item, "' is not KEY=VALUE (expected ", form, ")");
        }
        const std::string key = item.substr(0, eq);
        for (const auto& kv : out) {
            if (kv.first == key) Fail(flag, ": ", key, " is given twice");
        }
        out.emplace_back(key, item.substr(eq + 1));
        if (comma == std::string::npos) break;
        begin = comma + 1;
    }
    return out;
}

double ParseValue(const std::string& value, const char* flag, const std::string& key,
                  const char* range) {
    double v = 0.0;
    const NumberError e = ParseNumber(value, &v);
    if (e != NumberError::kNone) {
        Fail(flag, " ", key, "='", value, "' ", NumberErrorText(e), " (", key, ": ", range, ")");
    }
    return v;
}

void CheckRange(double v, double lo, double hi, bool open_lo, bool open_hi, const char* flag,
                const char* key, const char* unit) {
    const bool ok = (open_lo ? v > lo : v >= lo) && (open_hi ? v < hi : v <= hi);
    if (!ok) {
        Fail(flag, " ", key, " must be in ", open_lo ? "(" : "[", lo, ", ", hi, open_hi ? ")" : "]",
             unit, ", got ", v);
    }
}

constexpr const char* kCameraForm =
    "altitude=M,azimuth=DEG,elevation=DEG,roll=DEG,fov=DEG,projection=perspective|equirect|"
    "fisheye|cubemap|equal-area";

}  // namespace

const char* ProjectionName(Projection projection) {
    switch (projection) {
        case Projection::kPerspective:
            return "perspective";
        case Projection::kEquirect:
            return "equirect";
        case Projection::kFisheye:
            return "fisheye";
        case Projection::kCubemap:
            return "cubemap";
        case Projection::kEqualArea:
            return "equal-area";
    }
    return "?";
}

Vec3d DirectionFromAzimuthElevation(double azimuth_deg, double elevation_deg) {
    const double a = Radians(azimuth_deg);
    const double e = Radians(elevation_deg);
    return Vec3d(std::sin(a) * std::cos(e), std::cos(a) * std::cos(e), std::sin(e));
}

CameraSpec ParseCameraSpec(const std::string& text) {
    constexpr const char* kFlag = "--camera";
    CameraSpec spec;
    for (const auto& [key, value] : SplitKeyValues(text, kFlag, kCameraForm)) {
        if (key == "projection") {
            static const std::map<std::string, Projection> kNames = {
                {"perspective", Projection::kPerspective},
                {"equirect", Projection::kEquirect},
                {"fisheye", Projection::kFisheye},
                {"cubemap", Projection::kCubemap},
                {"equal-area", Projection::kEqualArea}};
            const auto it = kNames.find(value);
            if (it == kNames.end()) {
                Fail(kFlag, " projection='", value,
                     "' is not one of perspective, equirect, fisheye, cubemap, equal-area");
            }
            spec.projection = it->second;
        } else if (key == "altitude") {
            spec.altitude_m = ParseValue(value, kFlag, key, "metres above the ground, >= 0");
        } else if (key == "azimuth") {
            spec.azimuth_deg = ParseValue(value, kFlag, key, "degrees in [-360, 360]");
            spec.oriented = true;
        } else if (key == "elevation") {
            spec.elevation_deg = ParseValue(value, kFlag, key, "degrees in [-90, 90]");
            spec.oriented = true;
        } else if (key == "roll") {
            spec.roll_deg = ParseValue(value, kFlag, key, "degrees in [-180, 180]");
            spec.oriented = true;
        } else if (key == "fov") {
            spec.fov_deg = ParseValue(value, kFlag, key, "degrees");
            if (spec.fov_deg == 0.0) Fail(kFlag, " fov must be > 0 degrees, got 0");
        } else {
            Fail(kFlag, ": unknown key '", key,
                 "' (keys: altitude, azimuth, elevation, roll, fov, ", "projection)");
        }
    }
    return spec;
}

void CheckCameraSpec(const CameraSpec& spec, int width, int height) {
    constexpr const char* kFlag = "--camera";
    if (!std::isfinite(spec.altitude_m) || spec.altitude_m < 0.0) {
        Fail(kFlag, " altitude must be >= 0 m (the camera is above the ground), got ",
             spec.altitude_m);
    }
    CheckRange(spec.azimuth_deg, -360.0, 360.0, false, false, kFlag, "azimuth", " degrees");
    CheckRange(spec.elevation_deg, -90.0, 90.0, false, false, kFlag, "elevation", " degrees");
    CheckRange(spec.roll_deg, -180.0, 180.0, false, false, kFlag, "roll", " degrees");
    const char* name = ProjectionName(spec.projection);
    switch (spec.projection) {
        case Projection::kPerspective:
            if (spec.fov_deg != 0.0) {
                CheckRange(spec.fov_deg, 0.0, 180.0, true, true, kFlag, "fov", " degrees");
            }
            break;
        case Projection::kFisheye:
            if (spec.fov_deg != 0.0) {
                CheckRange(spec.fov_deg, 0.0, 360.0, true, false, kFlag, "fov", " degrees");
            }
            break;
        default:
            if (spec.fov_deg != 0.0) {
                Fail(kFlag, " fov applies to projection=perspective or fisheye, not ", name,
                     " (the whole sphere)");
            }
            break;
    }
    if (spec.oriented && spec.projection != Projection::kPerspective) {
        Fail(kFlag, " azimuth, elevation and roll apply to projection=perspective; ", name,
             " is world-aligned (north, east and the zenith fixed: docs/views.md)");
    }
    if (width <= 0 || height <= 0) return;
    if (spec.projection == Projection::kEquirect && width != 2 * height) {
        Fail(kFlag, " projection=equirect needs a 2:1 image (--size 2Hx H), got ", width, "x",
             height);
    }
    if (spec.projection == Projection::kCubemap && width != 6 * height) {
        Fail(kFlag,
             " projection=cubemap needs a 6:1 image (six H x H faces side by side: --size 6Hx H), "
             "got ",
             width, "x", height);
    }
    if (spec.projection == Projection::kEqualArea && width != height) {
        Fail(kFlag, " projection=equal-area needs a square image, got ", width, "x", height);
    }
}

Camera MakeCameraFromSpec(const CameraSpec& spec, const AtmosphereParameters& atmosphere) {
    CheckCameraSpec(spec, 0, 0);
    const Vec3d position(0.0, 0.0, atmosphere.bottom_radius + spec.altitude_m);
    Camera c;
    c.position = position;
    c.projection = spec.projection;
    if (spec.projection != Projection::kPerspective) {
        c.right = Vec3d(1.0, 0.0, 0.0);    // east
        c.forward = Vec3d(0.0, 1.0, 0.0);  // north
        c.up = Vec3d(0.0, 0.0, 1.0);       // zenith
        const double fov = spec.fov_deg > 0.0 ? spec.fov_deg : 180.0;
        c.half_fov = 0.5 * Radians(fov);
        return c;
    }
    // forward at (azimuth, elevation); up in the vertical plane through it
    // (well defined at the zenith and nadir too); right = forward x up.
    const double a = Radians(spec.azimuth_deg), e = Radians(spec.elevation_deg);
    const Vec3d horizontal(std::sin(a), std::cos(a), 0.0);
    const Vec3d zenith(0.0, 0.0, 1.0);
    const Vec3d forward = horizontal * std::cos(e) + zenith * std::sin(e);
    const Vec3d up = zenith * std::cos(e) - horizontal * std::sin(e);
    const Vec3d right = Cross(forward, up);
    // Roll: the camera turns clockwise about its view direction (as it sees
    // it), so its right side tips down.
    const double r = Radians(spec.roll_deg);
    c.forward = Normalize(forward);
    c.right = Normalize(right * std::cos(r) - up * std::sin(r));
    c.up = Normalize(up * std::cos(r) + right * std::sin(r));
    const double fov = spec.fov_deg > 0.0 ? spec.fov_deg : 60.0;
    c.tan_half_fov_y = std::tan(0.5 * Radians(fov));
    return c;
}

Vec3d ParseSunSpec(const std::string& text) {
    constexpr const char* kFlag = "--sun";
    constexpr const char* kForm =
        "elevation=DEG[,azimuth=DEG] or time=ISO-8601,latitude=DEG,longitude=DEG";
    // The date-and-place form: NREL's solar position (atmos/sun_position.h),
    // which checks its own keys (time, latitude, longitude, height, pressure,
    // temperature, delta-t) and names them in its errors.
    if (text.rfind("time=", 0) == 0 || text.find(",time=") != std::string::npos) {
        const SunPosition p = SunFromTimeSpec(text);
        return DirectionFromAzimuthElevation(p.azimuth_deg, p.elevation_deg);
    }
    bool has_elevation = false;
    double elevation = 0.0, azimuth = 0.0;
    for (const auto& [key, value] : SplitKeyValues(text, kFlag, kForm)) {
        if (key == "elevation") {
            elevation = ParseValue(value, kFlag, key, "degrees in [-90, 90]");
            CheckRange(elevation, -90.0, 90.0, false, false, kFlag, "elevation", " degrees");
            has_elevation = true;
        } else if (key == "azimuth") {
            azimuth = ParseValue(value, kFlag, key, "degrees clockwise from north in [-360, 360]");
            CheckRange(azimuth, -360.0, 360.0, false, false, kFlag, "azimuth", " degrees");
        } else if (key == "latitude" || key == "longitude") {
            Fail(kFlag, ": ", key, "= needs time= (expected ", kForm, ")");
        } else {
            Fail(kFlag, ": unknown key '", key,
                 "' (keys: elevation, azimuth; or time, latitude, longitude)");
        }
    }
    if (!has_elevation) Fail(kFlag, " needs elevation=DEG (expected ", kForm, ")");
    return DirectionFromAzimuthElevation(azimuth, elevation);
}

View CustomView(const CameraSpec& camera, const Vec3d& sun_direction,
                const AtmosphereParameters& atmosphere) {
    View v;
    v.name = "custom";
    v.description = std::string("free camera (") + ProjectionName(camera.projection) + ")";
    v.camera = MakeCameraFromSpec(camera, atmosphere);
    v.sun_direction = Normalize(sun_direction);
    v.sun_irradiance = 1.0;  // per unit solar irradiance (times the atmosphere's)
    v.exposure = 1.0f;
    v.sun_limb_darkening = kSunLimbDarkening;
    return v;
}

}  // namespace atmos
