// atmos: the per-ray contract between a model's evaluator and the loops.
//
// An evaluator is what a model hands the loops (render/render.h) for one
// render or sample. It is duck-typed, trivially copyable (it is passed to
// device kernels by value) and every member is ATMOS_HD:
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
//
// An evaluator that reads lookup tables names each of them (every TableView
// member) in
//   template <typename V> void VisitTables(V& v) { v(table_a); v(table_b); }
// as precomputation stages do (render/stages.h): the device launch re-points
// exactly the tables named there to their device copies.
//
// An evaluator for host use only (studies, tests), not a model of
// models/model_list.h, declares `static constexpr bool kHostOnly = true`: the
// CUDA build instantiates no kernels for it and a device launch of it fails.
//
// This header is physics: it includes nothing from render/ (a ctest checks
// that no header under physics/ does).
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>

#include "atmos/math.h"
#include "physics/geometry.h"

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
// atmosphere: *out is then the whole answer (L = 0, T = 1) except for a camera
// on the ground looking down (GroundAtCamera below), whose ground is still owed.
ATMOS_HD inline bool BeginRay(const Vec3d& camera, const Vec3d& dir, double bottom, double top,
                              RayResult* out, AtmosphereSegment* seg) {
    *out = RayResult();
    out->transmittance = Rgb(1.0f);
    *seg = ClipToAtmosphere(camera, dir, bottom, top);
    out->hits_ground = seg->hits_ground;
    return seg->inside;
}

// A camera on (or numerically below) the ground looking below its horizon:
// the ray ends on the ground at the camera itself. ClipToAtmosphere gives it
// an empty segment that ends on the ground (t_end = 0, hits_ground) and
// BeginRay returns false, but the ray still sees the ground: the evaluator
// shades the ground at the camera seen through no air (no sky, T = 1). The
// precomputation stages use ClipToAtmosphere unchanged.
ATMOS_HD inline bool GroundAtCamera(const AtmosphereSegment& seg) {
    return !seg.inside && seg.hits_ground;
}

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

// Evaluators with terms that depend on the view only (camera position and
// sun: e.g. a sky model's sun terms) declare
//   void PrepareView(const Vec3d& camera, const Vec3d& sun);
// the render loop calls it on its copy once per frame; Evaluate must still give
// the same answer for any other camera or sun (sample queries).
template <typename E, typename = void>
struct HasPrepareView : std::false_type {};
template <typename E>
struct HasPrepareView<E, std::void_t<decltype(std::declval<E&>().PrepareView(
                             std::declval<const Vec3d&>(), std::declval<const Vec3d&>()))>>
    : std::true_type {};
template <typename Evaluator>
inline void PrepareViewIfAny(Evaluator* evaluator, const Vec3d& camera, const Vec3d& sun) {
    if constexpr (HasPrepareView<Evaluator>::value) evaluator->PrepareView(camera, sun);
}

// True for evaluators that declare kHostOnly (no device kernels).
template <typename E, typename = void>
struct IsHostOnly : std::false_type {};
template <typename E>
struct IsHostOnly<E, std::void_t<decltype(E::kHostOnly)>>
    : std::integral_constant<bool, E::kHostOnly> {};

// True for evaluators with a VisitTables member (they hold lookup tables).
template <typename E, typename = void>
struct HasVisitTables : std::false_type {};
struct NoTableVisitor {
    template <typename T>
    void operator()(T&) const {}
};
template <typename E>
struct HasVisitTables<
    E, std::void_t<decltype(std::declval<E&>().VisitTables(std::declval<NoTableVisitor&>()))>>
    : std::true_type {};

// Calls e.VisitTables(v) when the evaluator holds tables; nothing otherwise.
template <typename E, typename V>
inline void VisitEvaluatorTables(E& e, V& v) {
    if constexpr (HasVisitTables<E>::value) e.VisitTables(v);
}

}  // namespace atmos
