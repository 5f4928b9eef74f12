// atmos: the per-pixel and per-query loops of wide channel batches
// (physics/wide.h): ShadePixel and SampleOne (render/render.h) for an
// evaluator of n channels, operation for operation per channel, so that a
// wide render's channel 3b + c is the three-channel render's channel c of
// batch b, bit for bit.
//
// A wide evaluator is trivially copyable and ATMOS_HD like any evaluator, with
//   int Channels() const;
//   void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
//                     bool want_ground, WideRayResult* out) const;
// The loops run on the CPU (ParallelFor); a spectral run takes the wide path
// on the CPU backend only (harness/spectral_run.h).
#pragma once

#include <cstdint>
#include <vector>

#include "atmos/model.h"
#include "base/parallel.h"
#include "physics/wide.h"
#include "render/render.h"

namespace atmos {

// PixelSetup with the irradiance of every channel.
struct WidePixelSetup {
    PixelSetup base;  // its Rgb irradiance is batch 0's; `irradiance` holds all
    float irradiance[kMaxWideChannels] = {};
};

// MakePixelSetup for `atmosphere` (any batch: the common fields) with each
// channel's solar irradiance from `w`.
inline WidePixelSetup MakeWidePixelSetup(const RenderRequest& request,
                                         const AtmosphereParameters& atmosphere,
                                         const WideCoefficients& w) {
    WidePixelSetup s;
    s.base = MakePixelSetup(request, atmosphere);
    for (int c = 0; c < w.channels; ++c) {
        s.irradiance[c] = static_cast<float>(w.solar_irradiance[c] * request.view.sun_irradiance);
    }
    return s;
}

// ShadePixel for every channel into out[0, Channels()).
template <typename Evaluator>
ATMOS_HD inline void ShadePixelWide(const Evaluator& evaluator, const WidePixelSetup& ws, int x,
                                    int y, float* out) {
    const PixelSetup& s = ws.base;
    const int n = evaluator.Channels();
    const Vec3d dir = s.camera.RayDirection(x, y, s.width, s.height);
    if (dir.x == 0.0 && dir.y == 0.0 && dir.z == 0.0) {
        for (int c = 0; c < n; ++c) out[c] = 0.0f;
        return;
    }
    WideRayResult r;
    evaluator.EvaluateWide(s.camera.position, dir, s.sun_direction, !s.transmittance, &r);
    if (s.transmittance) {
        for (int c = 0; c < n; ++c) out[c] = r.transmittance[c];
        return;
    }
    for (int c = 0; c < n; ++c) out[c] = (r.sky[c] + r.ground[c]) * ws.irradiance[c];
    if (s.sun_disc && !r.hits_ground && Dot(dir, s.sun_direction) >= s.cos_sun_radius) {
        if (s.limb_darkening == 0.0) {
            for (int c = 0; c < n; ++c) {
                out[c] += ws.irradiance[c] * r.transmittance[c] * s.sun_disc_scale;
            }
        } else {
            const double f =
                SunLimbFactor(Dot(dir, s.sun_direction), s.cos_sun_radius, s.limb_darkening);
            const float k = static_cast<float>(static_cast<double>(s.sun_disc_scale) * f);
            for (int c = 0; c < n; ++c) out[c] += ws.irradiance[c] * r.transmittance[c] * k;
        }
    }
}

// Renders every pixel, values[(y * width + x) * Channels() + c] (resized),
// then the output guard (GuardOutput).
template <typename Evaluator>
void RenderWideImage(const Evaluator& evaluator, const WidePixelSetup& setup,
                     std::vector<float>* values) {
    const int n = evaluator.Channels();
    const int64_t pixels = static_cast<int64_t>(setup.base.width) * setup.base.height;
    values->assign(static_cast<size_t>(pixels) * static_cast<size_t>(n), 0.0f);
    float* data = values->data();
    const int width = setup.base.width;
    ParallelFor(pixels, 256, [&](int64_t item) {
        const int x = static_cast<int>(item % width);
        const int y = static_cast<int>(item / width);
        ShadePixelWide(evaluator, setup, x, y, data + static_cast<size_t>(item) * n);
    });
    GuardOutput(values->data(), values->size());
}

// SampleOne's radiance for every channel: [query * Channels() + c], then the
// output guard.
template <typename Evaluator>
std::vector<float> SampleAllWide(const Evaluator& evaluator, double bottom_radius,
                                 const std::vector<SampleQuery>& queries) {
    const int n = evaluator.Channels();
    std::vector<float> out(queries.size() * static_cast<size_t>(n), 0.0f);
    float* data = out.data();
    ParallelFor(static_cast<int64_t>(queries.size()), 64, [&](int64_t item) {
        const SampleQuery& q = queries[static_cast<size_t>(item)];
        Vec3d dir, sun;
        SampleDirections(q, &dir, &sun);
        const Vec3d camera(0.0, 0.0, bottom_radius + q.altitude_m);
        const bool ground = q.ground != 0;
        WideRayResult r;
        evaluator.EvaluateWide(camera, dir, sun, ground, &r);
        float* a = data + static_cast<size_t>(item) * n;
        for (int c = 0; c < n; ++c) a[c] = ground ? r.sky[c] + r.ground[c] : r.sky[c];
    });
    GuardOutput(out.data(), out.size());
    return out;
}

// RenderWide and SampleWide of a model's PreparedWide; an atmos::Error naming
// `model` before its PrepareWide().
template <typename Evaluator>
void RenderPreparedWide(const char* model, const PreparedWide<Evaluator>& p,
                        const RenderRequest& request, std::vector<float>* values) {
    if (!p.prepared) Fail("model ", model, ": PrepareWide() must run before RenderWide()");
    RenderWideImage(p.evaluator, MakeWidePixelSetup(request, p.atmosphere, p.coefficients), values);
}
template <typename Evaluator>
std::vector<float> SamplePreparedWide(const char* model, const PreparedWide<Evaluator>& p,
                                      const std::vector<SampleQuery>& queries) {
    if (!p.prepared) Fail("model ", model, ": PrepareWide() must run before SampleWide()");
    return SampleAllWide(p.evaluator, p.atmosphere.bottom_radius, queries);
}

}  // namespace atmos
