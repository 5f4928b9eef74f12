// atmos: cameras and the 12 named views of seed 003 section 11.4.
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

// A pinhole camera: an orthonormal frame and the tangent of half the vertical
// field of view. The horizontal extent follows the image's aspect ratio.
struct Camera {
    Vec3d position;  // m, planet-centred
    Vec3d forward;   // unit: the direction of the image centre
    Vec3d right;     // unit: image +x
    Vec3d up;        // unit: image -y (rows go down)
    double tan_half_fov_y = 1.0;

    // Direction of the ray through pixel (x, y) of a width x height image, at
    // the pixel's centre offset by (dx, dy) in [0, 1) (0.5, 0.5: the centre).
    ATMOS_HD Vec3d RayDirection(int x, int y, int width, int height, double dx = 0.5,
                                double dy = 0.5) const {
        const double aspect = static_cast<double>(width) / height;
        const double u = (2.0 * (x + dx) / width - 1.0) * tan_half_fov_y * aspect;
        const double v = (1.0 - 2.0 * (y + dy) / height) * tan_half_fov_y;
        return Normalize(forward + right * u + up * v);
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
    float exposure = 1.0f;        // applied only when writing PNG
};

// The 12 views of DESIGN.md (ground-dawn ... orbit-noon, space,
// planet-shadow-ground, planet-shadow-orbit) for a planet with the given
// atmosphere (camera altitudes are measured from its bottom radius).
std::vector<View> StandardViews(const AtmosphereParameters& atmosphere);
std::vector<std::string> StandardViewNames();
// One view by name; throws atmos::Error listing the names if unknown.
View GetView(const std::string& name, const AtmosphereParameters& atmosphere);

}  // namespace atmos
