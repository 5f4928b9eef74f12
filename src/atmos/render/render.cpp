#include "render/render.h"

#include <cmath>

#include "atmos/error.h"

namespace atmos {

PixelSetup MakePixelSetup(const RenderRequest& request, const AtmosphereParameters& atmosphere) {
    PixelSetup s;
    s.camera = request.view.camera;
    s.sun_direction = Normalize(request.view.sun_direction);
    s.irradiance = Rgb(atmosphere.solar_irradiance * request.view.sun_irradiance);
    s.width = request.width;
    s.height = request.height;
    s.transmittance = request.quantity == Quantity::kTransmittance;
    s.sun_disc = request.sun_disc;
    const double alpha = atmosphere.sun_angular_radius;
    s.cos_sun_radius = std::cos(alpha);
    s.sun_disc_scale = static_cast<float>(1.0 / (kPi * alpha * alpha));
    return s;
}

void FailNoDeviceKernels(const char* evaluator) {
    Fail("device backend: evaluator ", evaluator,
         " has no device kernels (its model is not in src/atmos/models/model_list.h)");
}

}  // namespace atmos
