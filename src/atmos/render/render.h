// atmos: THE per-pixel loop.
//
// ShadePixel() is the one per-pixel function (ATMOS_HD): it asks a model's
// evaluator for the view ray's sky radiance, ground radiance and transmittance
// and composes the pixel. RenderImage() runs it over an image on the CPU
// (tiles, in parallel); the CUDA build launches the same ShadePixel() per thread
// (src/atmos/cuda). Models never see pixels.
//
// Evaluator contract (duck-typed, trivially copyable, every member ATMOS_HD):
//   RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
//                      bool want_ground) const;
// returning, per unit of solar irradiance, the light scattered into the ray by
// the atmosphere, the light reflected by the ground where the ray ends
// (attenuated to the camera; only when want_ground), and the transmittance of
// the ray's segment through the atmosphere (to the ground, or to space).
//
// Monte Carlo evaluators declare `static constexpr bool kStochastic = true` and
// implement instead
//   RayResult EvaluateKeyed(camera, dir, sun, want_ground, uint64_t key) const;
// where `key` identifies the pixel (or query) so that random numbers depend on
// the pixel and sample index only (src/atmos/base/rng.h).
#pragma once

#include <cstdint>
#include <type_traits>
#include <vector>

#include "atmos/image.h"
#include "atmos/math.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "physics/geometry.h"
#include "render/device_evaluators.h"

namespace atmos {

struct RayResult {
    Rgb sky;            // in-scattered radiance per unit solar irradiance
    Rgb ground;         // reflected ground radiance reaching the camera, same units
    Rgb transmittance;  // of the segment inside the atmosphere
    bool hits_ground = false;
};

// The opening every evaluator shares: clips the ray camera + t dir to the
// atmosphere shell [bottom, top] into *seg and resets *out (transmittance 1,
// hits_ground from the clip). Returns false when the ray does not cross the
// atmosphere: *out is then the whole answer (L = 0, T = 1).
ATMOS_HD inline bool BeginRay(const Vec3d& camera, const Vec3d& dir, double bottom, double top,
                              RayResult* out, AtmosphereSegment* seg) {
    *out = RayResult();
    out->transmittance = Rgb(1.0f);
    *seg = ClipToAtmosphere(camera, dir, bottom, top);
    out->hits_ground = seg->hits_ground;
    return seg->inside;
}

// Everything ShadePixel needs, trivially copyable (device-friendly).
struct PixelSetup {
    Camera camera;
    Vec3d sun_direction;
    Rgb irradiance;  // view irradiance x atmosphere solar irradiance
    int width = 0;
    int height = 0;
    bool transmittance = false;  // output the transmittance instead of radiance
    bool sun_disc = false;
    double cos_sun_radius = 1.0;  // cos(sun angular radius)
    float sun_disc_scale = 0.0f;  // 1 / (pi alpha^2): disc radiance per unit irradiance
};

PixelSetup MakePixelSetup(const RenderRequest& request, const AtmosphereParameters& atmosphere);

// True for evaluators that declare kStochastic (they take a pixel key).
template <typename E, typename = void>
struct IsStochastic : std::false_type {};
template <typename E>
struct IsStochastic<E, std::void_t<decltype(E::kStochastic)>>
    : std::integral_constant<bool, E::kStochastic> {};

template <typename Evaluator>
ATMOS_HD inline RayResult EvaluateRay(const Evaluator& evaluator, const Vec3d& camera,
                                      const Vec3d& dir, const Vec3d& sun, bool want_ground,
                                      uint64_t key) {
    if constexpr (IsStochastic<Evaluator>::value) {
        return evaluator.EvaluateKeyed(camera, dir, sun, want_ground, key);
    } else {
        (void)key;
        return evaluator.Evaluate(camera, dir, sun, want_ground);
    }
}

template <typename Evaluator>
ATMOS_HD inline Rgb ShadePixel(const Evaluator& evaluator, const PixelSetup& s, int x, int y) {
    const Vec3d dir = s.camera.RayDirection(x, y, s.width, s.height);
    const uint64_t key =
        static_cast<uint64_t>(y) * static_cast<uint64_t>(s.width) + static_cast<uint64_t>(x);
    const RayResult r =
        EvaluateRay(evaluator, s.camera.position, dir, s.sun_direction, !s.transmittance, key);
    if (s.transmittance) return SanitizeRadiance(r.transmittance);
    Rgb radiance = (r.sky + r.ground) * s.irradiance;
    if (s.sun_disc && !r.hits_ground && Dot(dir, s.sun_direction) >= s.cos_sun_radius) {
        radiance += s.irradiance * r.transmittance * s.sun_disc_scale;
    }
    return SanitizeRadiance(radiance);
}

#if defined(ATMOS_HAS_CUDA)
namespace cuda {
// Defined (and instantiated for ATMOS_DEVICE_EVALUATORS) in
// src/atmos/cuda/render_kernels.cu. Both copy the evaluator's tables to the
// device, run the kernel and copy the result back; throw atmos::Error on a
// CUDA error.
template <typename Evaluator>
void RenderImageDevice(const Evaluator& evaluator, const PixelSetup& setup, ImageView out);
template <typename Evaluator>
void SampleAllDevice(const Evaluator& evaluator, double bottom_radius, const SampleQuery* queries,
                     size_t count, SampleAnswer* answers);
}  // namespace cuda
#endif

// Throws the error of a device loop that cannot run: no CUDA in this build, or
// an evaluator without kernels (render/render.cpp).
[[noreturn]] void FailNoDeviceKernels(bool has_cuda);

// Renders every pixel of `out` (already sized s.width x s.height): on the CPU
// (the default), 16 x 16 tiles in parallel; each pixel depends on its
// coordinates only, so the image is the same for any thread count. On the
// CUDA backend, one thread per pixel on the device.
// `progress` (may be null) is advanced by one per pixel.
template <typename Evaluator>
void RenderImage(const Evaluator& evaluator, const PixelSetup& setup, ImageView out,
                 Progress* progress) {
    if (CurrentBackend() == Backend::kCuda) {
#if defined(ATMOS_HAS_CUDA)
        if constexpr (HasDeviceKernels<Evaluator>::value) {
            cuda::RenderImageDevice(evaluator, setup, out);
            if (progress) progress->Add(static_cast<int64_t>(setup.width) * setup.height);
            return;
        } else {
            FailNoDeviceKernels(true);
        }
#else
        FailNoDeviceKernels(false);
#endif
    }
    constexpr int kTile = 16;
    ParallelForTiles(setup.width, setup.height, kTile, [&](int x0, int y0, int x1, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) out.Set(x, y, ShadePixel(evaluator, setup, x, y));
        }
        if (progress) progress->Add(static_cast<int64_t>(x1 - x0) * (y1 - y0));
    });
}

template <typename Evaluator>
void RenderImage(const Evaluator& evaluator, const PixelSetup& setup, ImageView out,
                 bool show_progress) {
    Progress progress("render", static_cast<int64_t>(setup.width) * setup.height, show_progress);
    RenderImage(evaluator, setup, out, &progress);
}

// The sample contract of DESIGN.md for one query, through an evaluator.
template <typename Evaluator>
ATMOS_HD inline SampleAnswer SampleOne(const Evaluator& evaluator, double bottom_radius,
                                       const SampleQuery& q, uint64_t key = 0) {
    const double sin_v = SafeSqrt(1.0 - q.mu * q.mu);
    const double sin_s = SafeSqrt(1.0 - q.mu_s * q.mu_s);
    const double az = Radians(q.azimuth_deg);
    const Vec3d camera(0.0, 0.0, bottom_radius + q.altitude_m);
    const Vec3d dir(sin_v, 0.0, q.mu);
    const Vec3d sun(sin_s * cos(az), sin_s * sin(az), q.mu_s);
    const RayResult r = EvaluateRay(evaluator, camera, dir, sun, false, key);
    SampleAnswer a;
    a.radiance = SanitizeRadiance(r.sky);
    a.transmittance = r.hits_ground ? Rgb(0.0f) : SanitizeRadiance(r.transmittance);
    return a;
}

template <typename Evaluator>
std::vector<SampleAnswer> SampleAll(const Evaluator& evaluator, double bottom_radius,
                                    const std::vector<SampleQuery>& queries) {
    std::vector<SampleAnswer> answers(queries.size());
    if (CurrentBackend() == Backend::kCuda) {
#if defined(ATMOS_HAS_CUDA)
        if constexpr (HasDeviceKernels<Evaluator>::value) {
            cuda::SampleAllDevice(evaluator, bottom_radius, queries.data(), queries.size(),
                                  answers.data());
            return answers;
        } else {
            FailNoDeviceKernels(true);
        }
#else
        FailNoDeviceKernels(false);
#endif
    }
    ParallelFor(static_cast<int64_t>(queries.size()), 64, [&](int64_t i) {
        answers[static_cast<size_t>(i)] = SampleOne(
            evaluator, bottom_radius, queries[static_cast<size_t>(i)], static_cast<uint64_t>(i));
    });
    return answers;
}

// Host-side base for models with one evaluator: Render and Sample are written
// once here. Derived implements `Evaluator MakeEvaluator() const` and
// `const AtmosphereParameters& atmosphere() const`.
template <typename Derived>
class EvaluatorModel : public Model {
  public:
    void Render(const RenderRequest& request, Image* out) const override {
        const Derived& self = static_cast<const Derived&>(*this);
        const PixelSetup setup = MakePixelSetup(request, self.atmosphere());
        out->Resize(request.width, request.height);
        RenderImage(self.MakeEvaluator(), setup, out->View(), request.show_progress);
    }
    std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const override {
        const Derived& self = static_cast<const Derived&>(*this);
        return SampleAll(self.MakeEvaluator(), self.atmosphere().bottom_radius, queries);
    }
};

// The state most evaluator models are: their ModelInfo, the atmosphere of the
// last Prepare() and one evaluator, handed out by value. Derived provides
// `static ModelInfo StaticInfo()`, its constructor (from its options) and
// Prepare(), which sets atm_ and fills evaluator_.
template <typename Derived, typename Evaluator>
class SimpleEvaluatorModel : public EvaluatorModel<Derived> {
  public:
    const ModelInfo& Info() const override { return info_; }
    Evaluator MakeEvaluator() const { return evaluator_; }
    const AtmosphereParameters& atmosphere() const { return atm_; }

  protected:
    SimpleEvaluatorModel() : info_(Derived::StaticInfo()), atm_(EarthAtmosphere()) {}
    ModelInfo info_;
    AtmosphereParameters atm_;
    Evaluator evaluator_;
};

}  // namespace atmos
