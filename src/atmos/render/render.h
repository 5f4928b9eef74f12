// atmos: THE per-pixel and per-query loops.
//
// ShadePixel() is the one per-pixel function (ATMOS_HD): it asks a model's
// evaluator (the per-ray contract of physics/ray.h) for the view ray's sky
// radiance, ground radiance and transmittance and composes the pixel.
// SampleOne() is the one per-query function of the sample contract.
// RenderImage() and SampleAll() launch them through the one loop of the
// project, RunStage (render/stages.h), as the stages RenderStage (one item per
// pixel) and SampleStage (one item per query): that loop picks the backend
// (CPU: ParallelFor; CUDA: one thread per item, src/atmos/cuda/render_kernels.cu
// instantiates both stages for every evaluator of models/model_list.h;
// emulated device: the CUDA bookkeeping on the host), copies the evaluator's
// tables (those its VisitTables names) to the device through the current
// StageSession, and logs each launch ("render", "sample") in the stage log.
// Models never see pixels; the host adapters that turn an evaluator into a
// Model are in models/evaluator_model.h.
#pragma once

#include <string.h>

#include <cstdint>
#include <functional>
#include <typeinfo>
#include <vector>

#include "atmos/image.h"
#include "atmos/math.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/library_progress.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "base/rng.h"
#include "physics/geometry.h"
#include "physics/ray.h"
#include "render/stages.h"

namespace atmos {

// Everything ShadePixel needs, trivially copyable (device-friendly).
struct PixelSetup {
    Camera camera;
    Vec3d sun_direction;
    Rgb irradiance;  // view irradiance x atmosphere solar irradiance
    int width = 0;
    int height = 0;              // the camera's image; a render may cover a band of its rows
    int first_row = 0;           // the band's first row (RenderImage: `out` holds the band)
    bool transmittance = false;  // output the transmittance instead of radiance
    bool sun_disc = false;
    double cos_sun_radius = 1.0;  // cos(sun angular radius)
    float sun_disc_scale = 0.0f;  // 1 / (pi alpha^2): disc radiance per unit irradiance
    double limb_darkening = 0.0;  // View::sun_limb_darkening (0: a uniform disc)
};

// The disc's radiance relative to a uniform disc of the same irradiance at
// cos_angle from its centre: (1 - u (1 - mu)) / (1 - u / 3), mu = cos of the
// angle on the solar surface = sqrt(1 - (theta / alpha)^2), with
// (theta / alpha)^2 = (1 - cos theta) / (1 - cos alpha) (small angles).
ATMOS_HD inline double SunLimbFactor(double cos_angle, double cos_radius, double u) {
    const double x2 = Clamp((1.0 - cos_angle) / (1.0 - cos_radius), 0.0, 1.0);
    return (1.0 - u * (1.0 - Sqrt(1.0 - x2))) / (1.0 - u / 3.0);
}

PixelSetup MakePixelSetup(const RenderRequest& request, const AtmosphereParameters& atmosphere);

template <typename Evaluator>
ATMOS_HD inline Rgb ShadePixel(const Evaluator& evaluator, const PixelSetup& s, int x, int y) {
    const Vec3d dir = s.camera.RayDirection(x, y, s.width, s.height);
    // No ray (outside a fisheye's circle): black.
    if (dir.x == 0.0 && dir.y == 0.0 && dir.z == 0.0) return Rgb(0.0f);
    const uint64_t key =
        static_cast<uint64_t>(y) * static_cast<uint64_t>(s.width) + static_cast<uint64_t>(x);
    const RayResult r =
        EvaluateRay(evaluator, s.camera.position, dir, s.sun_direction, !s.transmittance, key);
    if (s.transmittance) return r.transmittance;
    Rgb radiance = (r.sky + r.ground) * s.irradiance;
    if (s.sun_disc && !r.hits_ground && Dot(dir, s.sun_direction) >= s.cos_sun_radius) {
        if (s.limb_darkening == 0.0) {
            radiance += s.irradiance * r.transmittance * s.sun_disc_scale;
        } else {
            const double f =
                SunLimbFactor(Dot(dir, s.sun_direction), s.cos_sun_radius, s.limb_darkening);
            radiance += s.irradiance * r.transmittance *
                        static_cast<float>(static_cast<double>(s.sun_disc_scale) * f);
        }
    }
    return radiance;  // RenderImage's output guard follows (GuardOutput)
}

// The key of a query's random numbers (Monte Carlo evaluators): a hash of
// the query itself, not of its place in the batch, so that a query's answer
// does not depend on the batch's size, order or other queries (issue 33);
// -0.0 counts as 0.0.
ATMOS_HD inline uint64_t SampleQueryKey(const SampleQuery& q) {
    const double fields[4] = {q.altitude_m + 0.0, q.mu + 0.0, q.mu_s + 0.0, q.azimuth_deg + 0.0};
    uint64_t key = 0x5A4D504C45ull;  // "SAMPLE"
    for (double f : fields) {
        uint64_t bits;
        memcpy(&bits, &f, sizeof(bits));
        key = Mix64(key ^ bits);
    }
    return key;
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
    const bool ground = q.ground != 0;
    const RayResult r = EvaluateRay(evaluator, camera, dir, sun, ground, key);
    SampleAnswer a;
    a.radiance = ground ? r.sky + r.ground : r.sky;
    a.transmittance = r.hits_ground ? Rgb(0.0f) : r.transmittance;
    return a;  // SampleAll's output guard follows (GuardOutput)
}

// The view and sun directions of a sample query (SampleOne's frame: the view
// in the x-z plane, the sun at azimuth_deg from it).
ATMOS_HD inline void SampleDirections(const SampleQuery& q, Vec3d* dir, Vec3d* sun) {
    const double sin_v = SafeSqrt(1.0 - q.mu * q.mu);
    const double sin_s = SafeSqrt(1.0 - q.mu_s * q.mu_s);
    const double az = Radians(q.azimuth_deg);
    *dir = Vec3d(sin_v, 0.0, q.mu);
    *sun = Vec3d(sin_s * cos(az), sin_s * sin(az), q.mu_s);
}

// The output guard (issue 18 item 3), the last step of every render and
// sample on every backend (on the host, after the launch): replaces each NaN,
// infinity and negative value of values[0, count) by 0 and returns how many it
// replaced, adding them to the process-wide count that OutputGuardCount()
// (atmos/model.h) reports. Models compute defined cases correctly and reject
// undefined input, so a non-zero count is a defect: the CLI warns (an error
// with --strict) and the test suite fails.
int64_t GuardOutput(float* values, size_t count);

// Throws the error of a device launch that cannot run: an evaluator without
// device kernels (not in models/model_list.h; render/render.cpp).
[[noreturn]] void FailNoDeviceKernels(const char* evaluator);
// Throws the error of a band of rows outside the image (RenderImage).
[[noreturn]] void FailBadBand(int width, int height, int first_row, int band_width, int band_rows);
// True for the evaluators of models/model_list.h (defined from the list in
// models/registry.cpp): the ones the CUDA build has kernels for.
bool HasDeviceKernels(const std::type_info& evaluator);

// One pixel per item (x fastest): the render as a stage of RunStage.
template <typename Evaluator>
struct RenderStage {
    Evaluator evaluator;
    PixelSetup setup;
    TableOut out;  // the band of rows [first_row, first_row + out.height): width x rows x 3
    // Its output and any id-0 view are copied back and dropped from the
    // session after the launch (render/stages.h).
    static constexpr bool kTransient = true;
    template <typename V>
    void VisitTables(V& v) {
        VisitEvaluatorTables(evaluator, v);
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const int x = static_cast<int>(item % setup.width);
        const int row = static_cast<int>(item / setup.width);
        const ImageView image{out.data, setup.width, out.height};
        image.Set(x, row, ShadePixel(evaluator, setup, x, setup.first_row + row));
    }
};

// One query per item: SampleAll as a stage of RunStage. The queries and
// answers travel as float tables (id 0: transient).
template <typename Evaluator>
struct SampleStage {
    static_assert(sizeof(SampleQuery) % sizeof(float) == 0, "queries travel as floats");
    static_assert(sizeof(SampleAnswer) % sizeof(float) == 0, "answers travel as floats");
    Evaluator evaluator;
    double bottom_radius = 0.0;
    TableView queries;
    TableOut answers;
    static constexpr bool kTransient = true;
    template <typename V>
    void VisitTables(V& v) {
        VisitEvaluatorTables(evaluator, v);
        v(queries);
        v(answers);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const SampleQuery* q = reinterpret_cast<const SampleQuery*>(queries.data);
        SampleAnswer* a = reinterpret_cast<SampleAnswer*>(answers.data);
        a[item] = SampleOne(evaluator, bottom_radius, q[item], SampleQueryKey(q[item]));
    }
};
// Every evaluator but host-only ones (physics/ray.h) has both launches on the
// device: render_kernels.cu instantiates them for the evaluators of
// models/model_list.h, so a CUDA build of a model missing from the list fails
// to link.
template <typename E>
struct HasDeviceStage<RenderStage<E>> : std::bool_constant<!IsHostOnly<E>::value> {};
template <typename E>
struct HasDeviceStage<SampleStage<E>> : std::bool_constant<!IsHostOnly<E>::value> {};

// Renders every pixel of `out` (already sized s.width x rows: the image's rows
// [s.first_row, s.first_row + rows), all of them by default) through
// RunStage("render", ...): each pixel depends on its coordinates only, so the
// image is the same for any backend schedule, thread count and split into
// bands. `progress` (may be null) is advanced by one per pixel.
template <typename Evaluator>
void RenderImage(const Evaluator& evaluator, const PixelSetup& setup, ImageView out,
                 Progress* progress) {
    if (IsDeviceBackend(CurrentBackend()) && !HasDeviceKernels(typeid(Evaluator))) {
        FailNoDeviceKernels(typeid(Evaluator).name());
    }
    RenderStage<Evaluator> stage{evaluator, setup, {}};
    PrepareViewIfAny(&stage.evaluator, setup.camera.position, setup.sun_direction);
    stage.out.data = out.data;
    stage.out.width = out.width;
    stage.out.height = out.height;
    stage.out.channels = 3;
    if (out.width != setup.width || setup.first_row < 0 || out.height < 0 ||
        setup.first_row + out.height > setup.height) {
        FailBadBand(setup.width, setup.height, setup.first_row, out.width, out.height);
    }
    RunStage("render", static_cast<int64_t>(setup.width) * out.height, 256, stage, progress);
    GuardOutput(out.data, static_cast<size_t>(out.width) * out.height * 3);
}

template <typename Evaluator>
void RenderImage(const Evaluator& evaluator, const PixelSetup& setup, ImageView out,
                 bool show_progress) {
    Progress progress("render", static_cast<int64_t>(setup.width) * setup.height, show_progress);
    RenderImage(evaluator, setup, out, &progress);
}

// Renders the whole image `out` (setup.first_row 0) by calling `render_band`
// on bands of its rows (the first of 16384 pixels, then of about a quarter of
// a second each at the rate measured), and between two bands stops with one
// atmos::Error naming `step` when a stop signal came (base/interrupt.h): long
// whole-image steps act on SIGINT within about a second at any size (issue 39
// item 1).
void ForEachInterruptibleBand(const PixelSetup& setup, ImageView out, const char* step,
                              const std::function<void(const PixelSetup&, ImageView)>& render_band);

// RenderImage in such bands, with a progress bar of its own labelled `step`.
// Each pixel depends on its coordinates only: the image is RenderImage's.
template <typename Evaluator>
void RenderImageInterruptible(const Evaluator& evaluator, const PixelSetup& setup, ImageView out,
                              bool show_progress, const char* step) {
    Progress progress(step, static_cast<int64_t>(setup.width) * out.height, show_progress);
    ForEachInterruptibleBand(setup, out, step, [&](const PixelSetup& band_setup, ImageView band) {
        RenderImage(evaluator, band_setup, band, &progress);
    });
}

// Answers every query through RunStage("sample", ...), advancing `progress`
// (may be null) by one per query.
template <typename Evaluator>
std::vector<SampleAnswer> SampleAll(const Evaluator& evaluator, double bottom_radius,
                                    const std::vector<SampleQuery>& queries, Progress* progress) {
    std::vector<SampleAnswer> answers(queries.size());
    if (queries.empty()) return answers;
    if (IsDeviceBackend(CurrentBackend()) && !HasDeviceKernels(typeid(Evaluator))) {
        FailNoDeviceKernels(typeid(Evaluator).name());
    }
    SampleStage<Evaluator> stage{evaluator, bottom_radius, {}, {}};
    constexpr int kQueryFloats = sizeof(SampleQuery) / sizeof(float);
    constexpr int kAnswerFloats = sizeof(SampleAnswer) / sizeof(float);
    stage.queries.data = reinterpret_cast<const float*>(queries.data());
    stage.queries.width = static_cast<int>(queries.size());
    stage.queries.channels = kQueryFloats;
    stage.answers.data = reinterpret_cast<float*>(answers.data());
    stage.answers.width = static_cast<int>(answers.size());
    stage.answers.channels = kAnswerFloats;
    RunStage("sample", static_cast<int64_t>(queries.size()), 64, stage, progress);
    GuardOutput(reinterpret_cast<float*>(answers.data()), answers.size() * kAnswerFloats);
    return answers;
}

// The same with a progress bar of its own for long batches (the CLI's
// `sample`, over a second; base/library_progress.h).
template <typename Evaluator>
std::vector<SampleAnswer> SampleAll(const Evaluator& evaluator, double bottom_radius,
                                    const std::vector<SampleQuery>& queries) {
    Progress progress("sample", static_cast<int64_t>(queries.size()), LibraryProgressEnabled());
    return SampleAll(evaluator, bottom_radius, queries, &progress);
}

}  // namespace atmos
