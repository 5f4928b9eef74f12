#include "render/render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "atmos/error.h"
#include "base/interrupt.h"

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
    s.limb_darkening = request.view.sun_limb_darkening;
    return s;
}

void AddSunDisc(const std::vector<SampleQuery>& queries, const AtmosphereParameters& atmosphere,
                std::vector<SampleAnswer>* answers, double limb_darkening) {
    const PixelSetup unit = [&] {
        RenderRequest request;
        request.view.sun_irradiance = 1.0;
        request.view.sun_limb_darkening = limb_darkening;
        PixelSetup s = MakePixelSetup(request, atmosphere);
        return s;
    }();
    for (size_t i = 0; i < queries.size() && i < answers->size(); ++i) {
        Vec3d dir, sun;
        SampleDirections(queries[i], &dir, &sun);
        SampleAnswer& a = (*answers)[i];
        // The transmittance is 0 for a ray that hits the ground: no disc.
        const double c = Dot(dir, sun);
        if (c >= unit.cos_sun_radius) {
            // As ShadePixel with irradiance 1.
            const double f = unit.limb_darkening == 0.0
                                 ? 1.0
                                 : SunLimbFactor(c, unit.cos_sun_radius, unit.limb_darkening);
            a.radiance +=
                a.transmittance * static_cast<float>(static_cast<double>(unit.sun_disc_scale) * f);
        }
    }
}

namespace {
std::atomic<int64_t> g_guarded{0};
}  // namespace

int64_t GuardOutput(float* values, size_t count) {
    int64_t replaced = 0;
    for (size_t i = 0; i < count; ++i) {
        const float v = values[i];
        if (!std::isfinite(v) || v < 0.0f) {
            values[i] = 0.0f;
            ++replaced;
        }
    }
    if (replaced > 0) g_guarded.fetch_add(replaced);
    return replaced;
}

int64_t OutputGuardCount() { return g_guarded.load(); }
void ResetOutputGuardCount(int64_t value) { g_guarded.store(value); }

void FailNoDeviceKernels(const char* evaluator) {
    Fail("device backend: evaluator ", evaluator,
         " has no device kernels (its model is not in src/atmos/models/model_list.h)");
}

void ForEachInterruptibleBand(
    const PixelSetup& setup, ImageView out, const char* step,
    const std::function<void(const PixelSetup&, ImageView)>& render_band) {
    using Clock = std::chrono::steady_clock;
    constexpr double kBandSeconds = 0.25;
    const int width = std::max(setup.width, 1);
    int rows = std::clamp(16384 / width, 1, std::max(out.height, 1));
    for (int row = 0; row < out.height;) {
        // Between bands (a step of one band runs as before, whatever the timing).
        if (const int signal_number = row > 0 ? StopSignalReceived() : 0) {
            Fail("interrupted by ", StopSignalName(signal_number), " during ", step, " (", row,
                 " of ", out.height,
                 " rows done; a checkpoint holds only whole passes' samples and bands: the same "
                 "command, with --resume where one was written, starts again)");
        }
        const int n = std::min(rows, out.height - row);
        PixelSetup band_setup = setup;
        band_setup.first_row = setup.first_row + row;
        const ImageView band{out.data + static_cast<size_t>(row) * out.width * 3, out.width, n};
        const auto start = Clock::now();
        render_band(band_setup, band);
        const double per_row = std::chrono::duration<double>(Clock::now() - start).count() / n;
        rows = per_row > 0.0 ? static_cast<int>(std::clamp(kBandSeconds / per_row, 1.0,
                                                           static_cast<double>(out.height)))
                             : out.height;
        row += n;
    }
}

void FailBadBand(int width, int height, int first_row, int band_width, int band_rows) {
    Fail("render: a band of ", band_width, "x", band_rows, " pixels from row ", first_row,
         " does not fit a ", width, "x", height, " image");
}

}  // namespace atmos
