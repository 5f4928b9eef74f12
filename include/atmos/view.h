// atmos: cameras and the 12 named views of Leenman's 2025 thesis section 11.4.
//
// The planet's centre is the origin and +z is the zenith of the reference
// point on the ground (0, 0, bottom_radius). Cameras are pinhole cameras with a
// fixed vertical field of view; docs/views.md gives every view's numbers.
#pragma once

#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/math.h"

namespace atmos {

// How a camera maps pixels to directions (docs/views.md draws each one).
// Every projection but kPerspective is world-aligned: it reads the camera's
// frame as right = east, forward = north, up = zenith (MakeWorldCamera).
enum class Projection : int {
    kPerspective = 0,  // pinhole: tan_half_fov_y, the image's aspect
    kEquirect = 1,     // column x: azimuth 360 (x + 0.5) / W clockwise from north;
                       // row y: elevation 90 - 180 (y + 0.5) / H (2:1 images)
    kFisheye = 2,      // equidistant, zenith at the centre, north up, east left;
                       // half_fov at half the image height; 0 outside that circle
    kCubemap = 3,      // a 6H x H strip of faces +X, -X, +Y, -Y, +Z, -Z (OpenGL's
                       // convention, GL +X = east, +Y = up, +Z = south)
    kEqualArea = 4,    // pbrt-v4's octahedral equal-area square (Clarberg 2008),
                       // its +x = east, +y = north, +z = up (square images)
};

// A camera: an orthonormal frame, a projection and its field of view.
struct Camera {
    Vec3d position;               // m, planet-centred
    Vec3d forward;                // unit: the direction of the image centre (world-aligned: north)
    Vec3d right;                  // unit: image +x (world-aligned: east)
    Vec3d up;                     // unit: image -y, rows go down (world-aligned: zenith)
    double tan_half_fov_y = 1.0;  // perspective
    Projection projection = Projection::kPerspective;
    double half_fov = 1.5707963267948966;  // fisheye: radians from the zenith at half the height

    // Direction of the ray through pixel (x, y) of a width x height image, at
    // the pixel's centre offset by (dx, dy) in [0, 1) (0.5, 0.5: the centre).
    // The zero vector where the projection has no ray (a fisheye's corners).
    ATMOS_HD Vec3d RayDirection(int x, int y, int width, int height, double dx = 0.5,
                                double dy = 0.5) const {
        if (projection == Projection::kPerspective) {
            const double aspect = static_cast<double>(width) / height;
            const double u = (2.0 * (x + dx) / width - 1.0) * tan_half_fov_y * aspect;
            const double v = (1.0 - 2.0 * (y + dy) / height) * tan_half_fov_y;
            return Normalize(forward + right * u + up * v);
        }
        const Vec3d local = MappedDirection(x + dx, y + dy, width, height);
        return right * local.x + forward * local.y + up * local.z;
    }

    // The world-aligned projections: the direction (east, north, up) at image
    // position (px, py) in pixels from the top-left corner.
    ATMOS_HD Vec3d MappedDirection(double px, double py, int width, int height) const {
        switch (projection) {
            case Projection::kEquirect: {
                const double azimuth = 2.0 * kPi * px / width;
                const double elevation = 0.5 * kPi - kPi * py / height;
                const double c = cos(elevation);
                return Vec3d(sin(azimuth) * c, cos(azimuth) * c, sin(elevation));
            }
            case Projection::kFisheye: {
                // u right, v up, in half-heights from the centre.
                const double u = (2.0 * px - width) / height;
                const double v = (height - 2.0 * py) / height;
                const double rho = sqrt(u * u + v * v);
                if (rho > 1.0) return Vec3d(0.0);  // outside the image circle
                const double zenith = rho * half_fov;
                if (rho == 0.0) return Vec3d(0.0, 0.0, 1.0);
                const double s = sin(zenith) / rho;
                return Vec3d(-u * s, v * s, cos(zenith));  // north up, east left
            }
            case Projection::kCubemap: {
                const int face = Clamp(static_cast<int>(px / height), 0, 5);
                // OpenGL's (s, t) in [0, 1], t = 0 on the face's first row.
                const double sc = 2.0 * (px - face * static_cast<double>(height)) / height - 1.0;
                const double tc = 2.0 * py / height - 1.0;
                // The GL direction whose major axis is the face (the inverse of
                // the GL 4.6 specification's table 8.19), in GL axes.
                const double gl[6][3] = {
                    {1.0, -tc, -sc},  // +X
                    {-1.0, -tc, sc},  // -X
                    {sc, 1.0, tc},    // +Y
                    {sc, -1.0, -tc},  // -Y
                    {sc, -tc, 1.0},   // +Z
                    {-sc, -tc, -1.0}  // -Z
                };
                // GL +X = east, +Y = up, +Z = south.
                return Normalize(Vec3d(gl[face][0], -gl[face][2], gl[face][1]));
            }
            case Projection::kEqualArea: {
                // Clarberg 2008, "Fast equal-area mapping of the (hemi)sphere
                // using SIMD", the octahedral form pbrt-v4 uses
                // (EqualAreaSquareToSphere): the square's diamond |u| + |v| <= 1
                // is the upper hemisphere, its corners the lower one.
                const double u = 2.0 * px / width - 1.0;
                const double v = 2.0 * py / height - 1.0;
                const double au = fabs(u), av = fabs(v);
                const double signed_distance = 1.0 - (au + av);
                const double r = 1.0 - fabs(signed_distance);
                const double phi = (r == 0.0 ? 1.0 : (av - au) / r + 1.0) * (0.25 * kPi);
                const double z = copysign(1.0 - r * r, signed_distance);
                const double s = r * SafeSqrt(2.0 - r * r);
                return Vec3d(copysign(cos(phi), u) * s, copysign(sin(phi), v) * s, z);
            }
            default:
                return Vec3d(0.0);
        }
    }
};

// Builds a camera at `position` looking along `forward` with `world_up` fixing
// the roll; vfov_deg is the vertical field of view in degrees.
Camera MakeCamera(const Vec3d& position, const Vec3d& forward, const Vec3d& world_up,
                  double vfov_deg);

struct View {
    std::string name;
    std::string description;
    Camera camera;
    Vec3d sun_direction;          // unit, toward the sun
    double sun_irradiance = 6.0;  // multiplies the atmosphere's solar irradiance
    // The sun's disc (--sun-disc): the linear limb-darkening coefficient u of
    // I(mu) / I(1) = 1 - u (1 - mu), normalised to the same irradiance (0: a
    // uniform disc, the 12 views; free views: kSunLimbDarkening).
    double sun_limb_darkening = 0.0;
    float exposure = 1.0f;  // applied only when writing PNG
};

// The limb darkening of free views' sun disc: the Eddington approximation of
// a grey atmosphere, I(mu) / I(1) = (2 + 3 mu) / 5 (u = 0.6; Mihalas,
// "Stellar Atmospheres", 1978, section 3-3), close to the Sun's measured
// visible-band limb darkening (Neckel & Labs 1994, Solar Physics 153).
constexpr double kSunLimbDarkening = 0.6;

// The 12 views of DESIGN.md (ground-dawn ... orbit-noon, space,
// planet-shadow-ground, planet-shadow-orbit) for a planet with the given
// atmosphere (camera altitudes are measured from its bottom radius).
std::vector<View> StandardViews(const AtmosphereParameters& atmosphere);
std::vector<std::string> StandardViewNames();
// One view by name; throws atmos::Error listing the names if unknown.
View GetView(const std::string& name, const AtmosphereParameters& atmosphere);

// A free camera (`--camera KEY=VALUE,...`, docs/views.md): `altitude_m` above
// the reference point (0, 0, R) of the planet, whose local frame is +x east,
// +y north, +z up. Perspective cameras look at `azimuth_deg` (clockwise from
// north) and `elevation_deg`, rolled by `roll_deg` (clockwise as the camera
// sees it), with a vertical field of view `fov_deg`; the other projections
// are world-aligned and take only `fov_deg` (fisheye: the angle across the
// image's height, default 180).
struct CameraSpec {
    double altitude_m = 0.0;
    double azimuth_deg = 0.0;
    double elevation_deg = 0.0;
    double roll_deg = 0.0;
    double fov_deg = 0.0;  // 0: the projection's default (perspective 60, fisheye 180)
    Projection projection = Projection::kPerspective;
    bool oriented = false;  // azimuth, elevation or roll was given
};
const char* ProjectionName(Projection projection);
// Parses "KEY=VALUE[,KEY=VALUE...]" (keys altitude, azimuth, elevation, roll,
// fov, projection); throws atmos::Error naming the key and its range.
CameraSpec ParseCameraSpec(const std::string& text);
// Throws atmos::Error when the spec is out of range or the image's size does
// not suit its projection (equirect 2:1, cubemap 6:1, equal-area square).
void CheckCameraSpec(const CameraSpec& spec, int width, int height);
Camera MakeCameraFromSpec(const CameraSpec& spec, const AtmosphereParameters& atmosphere);
// The unit vector at `azimuth_deg` clockwise from north (+y) toward east (+x)
// and `elevation_deg` above the horizon (z = 0).
Vec3d DirectionFromAzimuthElevation(double azimuth_deg, double elevation_deg);
// `--sun elevation=DEG,azimuth=DEG`: the direction toward the sun in the same
// frame. Throws atmos::Error naming the key and its range.
Vec3d ParseSunSpec(const std::string& text);
// A view of a free camera and sun (name "custom", sun irradiance 1, exposure 1).
View CustomView(const CameraSpec& camera, const Vec3d& sun_direction,
                const AtmosphereParameters& atmosphere);

}  // namespace atmos
