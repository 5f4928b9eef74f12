// atmos: the sun's direct and the sky's diffuse irradiance on a horizontal
// plane (`atmos irradiance`, Python atmos.irradiance; issue 31 item 3).
#pragma once

#include <string>

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "atmos/model.h"

namespace atmos {

struct HorizontalIrradiance {
    // Per channel, in the units of a free render (docs/views.md): per unit
    // solar irradiance times the atmosphere's solar_irradiance.
    Vec3d direct;   // E_sun T(sun) max(mu_s, 0): the sun lamp
    Vec3d diffuse;  // the integral of the model's sky radiance times mu over the upper hemisphere
    // The integral at half the nodes: its change bounds the quadrature's error.
    Vec3d diffuse_coarse;
    int mu_nodes = 0, azimuth_nodes = 0;
    bool has_table = false;  // the model's own table (Model::TableSkyIrradiance)
    Vec3d diffuse_table;
};

// The irradiance on a horizontal plane facing up at `altitude_m` for the sun
// `sun_elevation_deg` above the horizon, from a prepared model (any model: a
// Gauss-Legendre rule in mu on [0, 1] times the periodic trapezoidal rule in
// azimuth, doubled until the diffuse changes by less than `tolerance`
// (relative, largest channel) or 256 x 1024 nodes are reached).
HorizontalIrradiance ComputeHorizontalIrradiance(const Model& model,
                                                 const AtmosphereParameters& atmosphere,
                                                 double altitude_m, double sun_elevation_deg,
                                                 double tolerance = 1e-4);

// The CSV `atmos irradiance` prints: quantity,r,g,b; rows direct, diffuse and,
// with a table, diffuse_table ("%.9g").
std::string HorizontalIrradianceCsv(const HorizontalIrradiance& e);

}  // namespace atmos
