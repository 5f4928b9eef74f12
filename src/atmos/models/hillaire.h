// atmos model `hillaire`: Hillaire 2020's LUT-based sky and aerial perspective.
//
// Source: S. Hillaire, "A Scalable and Production Ready Sky and Atmosphere
// Rendering Technique", EGSR 2020 (Computer Graphics Forum 39(4)); Leenman's 2025 thesis
// sections 5.2 (Eq. 31), 11.2.4, 11.6, 12.1.1, 12.3; the transmittance table's
// mapping is Bruneton 2017, GetTransmittanceTextureUvFromRMu.
//
// Implements, per unit of solar irradiance:
//  * Transmittance table T(r, mu) to the top of the atmosphere, 256 x 64, seed
//    004's (x_mu, x_r) mapping with texel-centre coordinates; optical depth by
//    the midpoint rule (`--transmittance-steps`, 40 as in the paper's demo).
//  * Multiple-scattering table Psi_ms(r, mu_s), 32 x 32 over altitude and sun
//    zenith cosine (u = 0.5 mu_s + 0.5, v = altitude / thickness, texel
//    centres): at each texel, 64 directions (8 x 8 stratified, uniform on the
//    sphere) are ray marched (20 steps each) to get
//      L_2nd = int_Omega L'(x, -w) p_u dw                     (paper Eq. 5-6)
//      L'(x, v) = int T(x, y) sigma_s(y) p_u T_sun(y) V(y) dt + T(x, g) a/pi (n.s) T_sun(g)
//      f_ms = int_Omega p_u int sigma_s(y) T(x, y) dt dw       (paper Eq. 7-8)
//      Psi_ms = L_2nd / (1 - f_ms)                             (paper Eq. 9-10; Leenman's 2025
//      thesis Eq. 31)
//    with the isotropic phase p_u = 1/(4 pi), the planet shadow V and the
//    ground albedo a (Lambertian, lit by the transmitted sun).
//  * The ray march (paper Eq. 1-3, 11): along the segment inside the atmosphere,
//    N equal segments each sampled at a fraction `--segment-offset` of its
//    length (0.3, the demo's SampleSegmentT; 0.5 is the midpoint rule), with
//      S = T_sun V (sigma_R P_R(nu) + sigma_M P_M(nu)) + (sigma_R + sigma_M) Psi_ms
//    integrated analytically over each segment at constant coefficients,
//      L += T_acc (S - S e^(-sigma_t dt)) / sigma_t,  T_acc *= e^(-sigma_t dt)
//    (Hillaire 2015, "energy-conserving" integration, used by the paper).
//    T_sun from the transmittance table, Psi_ms from the multiple-scattering
//    table, Rayleigh phase and Cornette-Shanks for Mie (one or two lobes,
//    physics/phase.h MiePhase).
//  * Sky-view table (per frame: depends on the camera's altitude and the sun's
//    zenith angle), 192 x 108: u = sqrt(0.5 - 0.5 cos(azimuth to the sun)),
//    v < 0.5 above the horizon with v = 0.5 (1 - sqrt(1 - theta / theta_h)),
//    v > 0.5 below it with v = 0.5 + 0.5 sqrt((theta - theta_h) / beta)
//    (theta: view zenith angle, theta_h = pi - beta the horizon's, cos beta =
//    sqrt(r^2 - R^2) / r): the paper's non-linear latitude mapping, texels
//    concentrated at the horizon; each texel one ray march (`--sky-view-steps`,
//    30), without ground reflection.
//  * Aerial-perspective volume (per frame: depends on the camera frustum),
//    32 x 32 x 32 froxels over screen (u, v) and distance: slice centre k at
//    distance ((k + 0.5) / 32)^2 32 D (D = `--ap-km-per-slice`, 4 km), i.e.
//    w = sqrt(d / (32 D)); RGB in-scattering and RGB transmittance (two tables).
//
// Rendering (HillaireEvaluator::Evaluate):
//  * camera inside the atmosphere (r <= top) with frame tables: sky from the
//    sky-view table, transmittance from the transmittance table; a ray that
//    hits the ground gets its in-scatter and transmittance from the aerial-
//    perspective volume when the ground is within the volume's last slice
//    (`--ground-path aerial-perspective`, the default), otherwise from the
//    sky-view table (its lower half marches to the ground) and the
//    transmittance table (T(r,mu,d) = T(r_d,-mu_d)/T(r,-mu), Bruneton's 2017 implementation notes);
//    between the centres of slices 24 and 31 the two are blended linearly
//    (no seam where the volume ends; the paper leaves this to the engine);
//    `--ground-path sky-view` uses the latter for every ground ray. The
//    froxel rays of the volume ignore the ground (a point below it is taken
//    at the ground): a ground ray's value is interpolated between froxel
//    columns, and columns that stopped at their own, nearer ground hit (as in
//    the demo, whose depth buffer holds the scene) bias the planet's ground
//    by ~5 % on average and up to 30 % near the horizon; with rays through
//    the ground the bias is 0.3 % / 3 % (tests/hillaire_test.cpp);
//  * camera outside (orbit, space), or no frame tables: the ray march with
//    `--steps` (40, the thesis's count) from where the ray enters;
//  * lit ground (albedo > 0): a/pi max(0, n.s) T_sun(ground) times the view
//    transmittance, direct sun only (as the paper's demo); the sun disc is the
//    render loop's (--sun-disc).
//
// Output: radiance per unit solar irradiance (1/sr) and the segment's RGB
// transmittance. Valid: any camera and sun; multiple scattering approximated
// (isotropic after the first bounce), so the Mie halo around a low sun differs
// from the path tracer (Leenman's 2025 thesis section 12.1.1).
//
// Deviations from the paper's demo: geometry in double, tables in float; the
// sky-view table is built for a camera at least 1 m above the ground (the
// demo offsets the camera by 10 m); the aerial-perspective volume is built
// by one cumulative march per screen column (`--ap-steps-per-slice` segments
// per slice, 4) instead of one march per froxel, lets the froxel rays pass
// through the ground (above), blends to the sky-view path near its far end,
// stores RGB transmittance instead of its mean, and fades linearly from the
// camera to the first slice centre (the demo fades over half a slice); no
// variable sample count (fixed step counts, options); the ground is lit by the
// direct sun only. Kept from the demo: samples at 0.3 of each segment, which
// biases coarse marches (a 40-step march's transmittance on grazing rays by up
// to 13 %, the multiple-scattering table by up to 11 %, against 0.5; see
// tests/hillaire_test.cpp); `--segment-offset 0.5` gives the midpoint rule.
//
// Sample(): each query has its own altitude and sun. With `--sample-path table`
// (default) the queries are grouped by (altitude, mu_s) and one sky-view table
// is built per group inside the atmosphere (what a renderer would do per frame;
// the table is relative to the sun's azimuth); no aerial-perspective volume, so
// ground-hitting rays use the sky-view table's lower half; each group's
// queries go through the one launch (SampleAll, render/render.h) with that
// table. `--sample-path march` ray marches every query (no per-frame tables).
// On a device backend the model's two tables stay on the device from
// Prepare() to its renders and samples (ResidentTables, render/stages.h).
//
// Precomputation: the four tables (transmittance, multiple scattering, and per
// frame sky-view and aerial perspective) are built by the stage structs of
// hillaire_stages.h through RunStage: on the CPU, or, on the CUDA backend
// (`--backend cuda`), on the device from the same code.
//
// Wide channel batches (a spectral run's up to 16 batches of three in one
// model: PrepareWide, RenderWide, SampleWide): hillaire_wide.h, every table
// and lookup with n channels, bit for bit the batches' values.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/texture.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/vector_exp.h"
#include "physics/wide.h"

#include "base/non_copyable.h"

namespace atmos {

// Table sizes (paper section 5 and the issue).
constexpr int kHillaireTransmittanceWidth = 256;
constexpr int kHillaireTransmittanceHeight = 64;
constexpr int kHillaireMsSize = 32;
constexpr int kHillaireMsSqrtDirections = 8;  // 64 directions
constexpr int kHillaireMsSteps = 20;          // the demo's march per direction
constexpr int kHillaireSkyViewWidth = 192;
constexpr int kHillaireSkyViewHeight = 108;
constexpr int kHillaireApSize = 32;
constexpr int kHillaireApBlendSlice =
    24;  // ground rays blend to the sky-view path from here                  // x, y and slices
constexpr double kHillaireSkyViewMinAltitude = 1.0;  // m, for the horizon angle

// --- Table mappings (all ATMOS_HD) -----------------------------------------

// Bruneton's 2017 implementation notes GetTransmittanceTextureUvFromRMu.
ATMOS_HD inline void HillaireTransmittanceUv(const AtmosphereParameters& atm, double r, double mu,
                                             double* u, double* v) {
    const double bottom = atm.bottom_radius, top = atm.top_radius;
    r = Clamp(r, bottom, top);
    const double H = Sqrt(top * top - bottom * bottom);
    const double rho = SafeSqrt(r * r - bottom * bottom);
    const double d = DistanceToTopAtmosphereBoundary(r, ClampCosine(mu), top);
    const double d_min = top - r;
    const double d_max = rho + H;
    const double x_mu = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
    *u = GetTextureCoordFromUnitRange(Clamp(x_mu, 0.0, 1.0), kHillaireTransmittanceWidth);
    *v = GetTextureCoordFromUnitRange(rho / H, kHillaireTransmittanceHeight);
}

// Bruneton's 2017 implementation notes GetRMuFromTransmittanceTextureUv: unit coordinates (x_mu,
// x_r) -> (r, mu).
ATMOS_HD inline void HillaireTransmittanceRMu(const AtmosphereParameters& atm, double x_mu,
                                              double x_r, double* r, double* mu) {
    const double bottom = atm.bottom_radius, top = atm.top_radius;
    const double H = Sqrt(top * top - bottom * bottom);
    const double rho = H * x_r;
    *r = Sqrt(rho * rho + bottom * bottom);
    const double d_min = top - *r;
    const double d_max = rho + H;
    const double d = d_min + x_mu * (d_max - d_min);
    *mu = d == 0.0 ? 1.0 : ClampCosine((H * H - rho * rho - d * d) / (2.0 * *r * d));
}

// Multiple-scattering table (paper section 5.5.2): u = 0.5 mu_s + 0.5,
// v = altitude / thickness, both on texel centres.
ATMOS_HD inline void HillaireMsUv(const AtmosphereParameters& atm, double r, double mu_s, double* u,
                                  double* v) {
    const double x = Clamp(0.5 * mu_s + 0.5, 0.0, 1.0);
    const double y =
        Clamp((r - atm.bottom_radius) / (atm.top_radius - atm.bottom_radius), 0.0, 1.0);
    *u = GetTextureCoordFromUnitRange(x, kHillaireMsSize);
    *v = GetTextureCoordFromUnitRange(y, kHillaireMsSize);
}

// Sky-view horizon geometry at radius r (paper section 5.3): beta is the angle
// between the horizontal and the direction to the horizon; theta_h = pi - beta.
ATMOS_HD inline void HillaireSkyViewHorizon(double r, double bottom, double* beta,
                                            double* theta_h) {
    const double r_eff = Max(r, bottom + kHillaireSkyViewMinAltitude);
    const double cos_beta = Sqrt(r_eff * r_eff - bottom * bottom) / r_eff;
    *beta = acos(Clamp(cos_beta, -1.0, 1.0));
    *theta_h = kPi - *beta;
}

// (view zenith cosine, cosine of the azimuth between view and sun) -> texture
// coordinates of the sky-view table (paper section 5.3, non-linear latitude).
ATMOS_HD inline void HillaireSkyViewUv(double r, double bottom, double mu_v, double cos_az,
                                       double* u, double* v) {
    double beta, theta_h;
    HillaireSkyViewHorizon(r, bottom, &beta, &theta_h);
    const double theta = acos(ClampCosine(mu_v));
    double y;
    if (theta <= theta_h) {
        const double c = Clamp(theta / theta_h, 0.0, 1.0);
        y = 0.5 * (1.0 - SafeSqrt(1.0 - c));
    } else {
        const double c = Clamp((theta - theta_h) / beta, 0.0, 1.0);
        y = 0.5 + 0.5 * Sqrt(c);
    }
    const double x = SafeSqrt(0.5 - 0.5 * ClampCosine(cos_az));
    *u = GetTextureCoordFromUnitRange(x, kHillaireSkyViewWidth);
    *v = GetTextureCoordFromUnitRange(y, kHillaireSkyViewHeight);
}

// The inverse on unit coordinates (x, y) in [0, 1]: -> (mu_v, cos_az).
ATMOS_HD inline void HillaireSkyViewParams(double r, double bottom, double x, double y,
                                           double* mu_v, double* cos_az) {
    double beta, theta_h;
    HillaireSkyViewHorizon(r, bottom, &beta, &theta_h);
    double theta;
    if (y < 0.5) {
        const double c = 1.0 - 2.0 * y;
        theta = theta_h * (1.0 - c * c);
    } else {
        const double c = 2.0 * y - 1.0;
        theta = theta_h + beta * c * c;
    }
    *mu_v = cos(theta);
    *cos_az = ClampCosine(1.0 - 2.0 * x * x);
}

// Distance of the aerial-perspective slice centre k (paper section 5.4 and its
// demo: squared distribution of slices).
ATMOS_HD inline double HillaireApSliceDistance(int k, double metres_per_slice) {
    const double w = (k + 0.5) / kHillaireApSize;
    return w * w * kHillaireApSize * metres_per_slice;
}

// --- The evaluator ------------------------------------------------------------

struct HillaireEvaluator {
    AtmosphereParameters atm;
    TableView transmittance;              // 256 x 64, RGB
    TableView multiple_scattering;        // 32 x 32, RGB Psi_ms
    int steps = 40;                       // ray march outside the atmosphere / without tables
    bool use_multiple_scattering = true;  // false: single scattering only (tests)
    double segment_offset = 0.3;          // sample position inside each march segment
    bool ground_from_ap = true;  // ground rays: aerial perspective (true) or sky-view table
    // > 0 and no sky-view table (sample-path=table): each lookup computes the
    // sky-view texels it reads, with this many steps each, for its own camera
    // and sun (SkyView): the same bits as the frame table a render at that
    // camera and sun would build, whatever the other queries of the batch.
    int per_query_sky_view_steps = 0;

    // Per-frame tables (data == nullptr: absent).
    TableView sky_view;          // 192 x 108, RGB
    TableView ap_scatter;        // 32 x 32 x 32, RGB
    TableView ap_transmittance;  // 32 x 32 x 32, RGB
    Camera ap_camera;            // the frustum the volume was built for
    double ap_aspect = 1.0;
    double ap_metres_per_slice = 4000.0;

    // Names every table (physics/ray.h: the device launch re-points these).
    template <typename V>
    void VisitTables(V& v) {
        v(transmittance);
        v(multiple_scattering);
        v(sky_view);
        v(ap_scatter);
        v(ap_transmittance);
    }

    ATMOS_HD Vec3d Transmittance(double r, double mu) const {
        double u, v;
        HillaireTransmittanceUv(atm, r, mu, &u, &v);
        return Vec3d(SampleBilinearRgb(transmittance, u, v));
    }

    // Transmittance of a segment of length d from (r, mu) that ends on the
    // ground (Bruneton's 2017 implementation notes GetTransmittance with
    // ray_r_mu_intersects_ground).
    ATMOS_HD Vec3d TransmittanceToGround(double r, double mu, double d) const {
        const double r_d =
            Clamp(Sqrt(d * d + 2.0 * r * mu * d + r * r), atm.bottom_radius, atm.top_radius);
        const double mu_d = ClampCosine((r * mu + d) / r_d);
        const Vec3d a = Transmittance(r_d, -mu_d);
        const Vec3d b = Transmittance(r, -mu);
        Vec3d t;
        for (int c = 0; c < 3; ++c) t[c] = b[c] > 0.0 ? Min(a[c] / b[c], 1.0) : 0.0;
        return t;
    }

    // Sun transmittance times the planet's shadow at radius r, sun cosine mu_s.
    ATMOS_HD Vec3d SunTransmittance(double r, double mu_s) const {
        if (RayIntersectsGround(r, ClampCosine(mu_s), atm.bottom_radius)) return Vec3d(0.0);
        return Transmittance(r, mu_s);
    }

    ATMOS_HD Vec3d MultipleScattering(double r, double mu_s) const {
        if (!use_multiple_scattering) return Vec3d(0.0);
        double u, v;
        HillaireMsUv(atm, r, mu_s, &u, &v);
        return Vec3d(SampleBilinearRgb(multiple_scattering, u, v));
    }

    // Integrates the in-scattered radiance over [ta, tb] of origin + t dir in
    // `n` equal segments (paper Eq. 11 with the analytic per-segment
    // integration); adds to *L and multiplies *T (the throughput from the
    // camera to ta on entry).
    // With `through_ground`, points below the ground are taken at the ground
    // (used by the aerial-perspective volume, see BuildFrame).
    ATMOS_HD void Integrate(const Vec3d& origin, const Vec3d& dir, const Vec3d& sun, double ta,
                            double tb, int n, Vec3d* L, Vec3d* T,
                            bool through_ground = false) const {
        if (!(tb > ta) || n < 1) return;
        const double nu = Dot(dir, sun);
        const double phase_r = RayleighPhase(nu);
        const double phase_m = MiePhase(atm, nu);
        const double dt = (tb - ta) / n;
        for (int i = 0; i < n; ++i) {
            Vec3d p = origin + dir * (ta + (i + segment_offset) * dt);
            double r = Length(p);
            if (through_ground && r < atm.bottom_radius) {
                p = p * (atm.bottom_radius / r);
                r = atm.bottom_radius;
            }
            const double mu_s = ClampCosine(Dot(p, sun) / r);
            const Densities d = GetDensities(atm, r - atm.bottom_radius);
            const Vec3d sigma_r = atm.rayleigh_scattering * d.rayleigh;
            const Vec3d sigma_m = atm.mie_scattering * d.mie;
            const Vec3d sigma_t = Extinction(atm, d);
            const Vec3d t_sun = SunTransmittance(r, mu_s);
            const Vec3d psi = MultipleScattering(r, mu_s);
            const Vec3d S =
                t_sun * (sigma_r * phase_r + sigma_m * phase_m) + (sigma_r + sigma_m) * psi;
            // ExpLane (physics/vector_exp.h): the wide evaluator's channels
            // take the same exponential as one vector loop.
            const Vec3d step_t = ExpLane(-sigma_t * dt);
            for (int c = 0; c < 3; ++c) {
                const double s_int =
                    sigma_t[c] > 0.0 ? (S[c] - S[c] * step_t[c]) / sigma_t[c] : S[c] * dt;
                (*L)[c] += (*T)[c] * s_int;
            }
            *T *= step_t;
        }
    }

    // Light reflected by the ground point g toward the camera, before the view
    // transmittance (Lambertian, direct sun).
    ATMOS_HD Vec3d GroundReflection(const Vec3d& g, const Vec3d& sun) const {
        const Vec3d n = Normalize(g);
        const double cos_sun = Dot(n, sun);
        if (cos_sun <= 0.0) return Vec3d(0.0);
        return atm.ground_albedo * (cos_sun / kPi) * Transmittance(atm.bottom_radius, cos_sun);
    }

    // Sky-view lookup for a camera at radius r (the table's), in the local frame.
    ATMOS_HD Vec3d SkyView(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun) const {
        const double r = Length(camera);
        const Vec3d up = camera / r;
        const double mu_v = ClampCosine(Dot(dir, up));
        const Vec3d dir_h = dir - up * Dot(dir, up);
        const Vec3d sun_h = sun - up * Dot(sun, up);
        const double lh = Length(dir_h) * Length(sun_h);
        const double cos_az = lh > 1e-12 ? ClampCosine(Dot(dir_h, sun_h) / lh) : 1.0;
        double u, v;
        HillaireSkyViewUv(r, atm.bottom_radius, mu_v, cos_az, &u, &v);
        if (sky_view.data != nullptr) return Vec3d(SampleBilinearRgb(sky_view, u, v));
        // No table: the four texels of this lookup, computed here exactly as
        // HillaireSkyViewStage computes them for the frame of this camera and
        // sun (HillaireModel::BuildFrame), then the same bilinear blend on a
        // 2 x 2 table (same operations, same bits).
        const TexelSpan sx = SplitSpan(u, kHillaireSkyViewWidth);
        const TexelSpan sy = SplitSpan(v, kHillaireSkyViewHeight);
        const double mu_s = ClampCosine(Dot(sun, camera) / r);
        const Vec3d sun_xz(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        const double r_table = Max(r, atm.bottom_radius + kHillaireSkyViewMinAltitude);
        float texels[2 * 2 * 3];
        for (int row = 0; row < 2; ++row) {
            for (int col = 0; col < 2; ++col) {
                const int i = col == 0 ? sx.i0 : sx.i1, j = row == 0 ? sy.i0 : sy.i1;
                const Vec3d L = (col == 1 && sx.i1 == sx.i0) || (row == 1 && sy.i1 == sy.i0)
                                    ? Vec3d(0.0)  // not read (the span's weight is on i0)
                                    : SkyViewTexel(r_table, sun_xz, per_query_sky_view_steps, i, j);
                float* t = texels + (row * 2 + col) * 3;
                for (int c = 0; c < 3; ++c) t[c] = static_cast<float>(L[c]);
            }
        }
        TexelSpan x2 = sx, y2 = sy;
        x2.i0 = 0;
        x2.i1 = sx.i1 == sx.i0 ? 0 : 1;
        y2.i0 = 0;
        y2.i1 = sy.i1 == sy.i0 ? 0 : 1;
        float o[3];
        SampleBilinearFixed<3>(texels, 2, x2, y2, o);
        return Vec3d(Rgb(o[0], o[1], o[2]));
    }

    // Sky-view texel (i, j) for a camera at radius r (raised to
    // kHillaireSkyViewMinAltitude) on the z axis and the sun `sun` in the x-z
    // plane: one ray march of `march_steps` segments (paper section 5.3, Eq. 11),
    // without ground reflection. Reads only the model's two tables.
    ATMOS_HD Vec3d SkyViewTexel(double r, const Vec3d& sun, int march_steps, int i, int j) const {
        const Vec3d camera(0.0, 0.0, r);
        double mu_v, cos_az;
        HillaireSkyViewParams(
            r, atm.bottom_radius, static_cast<double>(i) / (kHillaireSkyViewWidth - 1),
            static_cast<double>(j) / (kHillaireSkyViewHeight - 1), &mu_v, &cos_az);
        const double sin_v = SafeSqrt(1.0 - mu_v * mu_v);
        const Vec3d dir(sin_v * cos_az, sin_v * SafeSqrt(1.0 - cos_az * cos_az), mu_v);
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        Vec3d L, T(1.0);
        if (seg.inside) Integrate(camera, dir, sun, seg.t_start, seg.t_end, march_steps, &L, &T);
        return L;
    }

    // Aerial perspective to distance d along dir; false when dir is outside the
    // frustum or d beyond the last slice centre.
    ATMOS_HD bool AerialPerspective(const Vec3d& dir, double d, Vec3d* scatter,
                                    Vec3d* trans) const {
        if (ap_scatter.data == nullptr) return false;
        const double a = Dot(dir, ap_camera.forward);
        if (a <= 0.0) return false;
        const double tan_y = ap_camera.tan_half_fov_y;
        const double u = 0.5 * (Dot(dir, ap_camera.right) / (a * tan_y * ap_aspect) + 1.0);
        const double v = 0.5 * (1.0 - Dot(dir, ap_camera.up) / (a * tan_y));
        const double d_last = HillaireApSliceDistance(kHillaireApSize - 1, ap_metres_per_slice);
        if (d > d_last) return false;
        const double d_first = HillaireApSliceDistance(0, ap_metres_per_slice);
        const double dd = Max(d, d_first);
        const double w = Sqrt(dd / (kHillaireApSize * ap_metres_per_slice));
        // One split for both volumes (same size, 3 channels; fixed layout).
        const TexelSpan sx = SplitSpan(u, ap_scatter.width), sy = SplitSpan(v, ap_scatter.height);
        const TexelSpan sz = SplitSpan(w, ap_scatter.depth);
        float fs[3], ft[3];
        SampleTrilinearFixed<3>(ap_scatter.data, ap_scatter.width, ap_scatter.height, sx, sy, sz,
                                fs);
        SampleTrilinearFixed<3>(ap_transmittance.data, ap_scatter.width, ap_scatter.height, sx, sy,
                                sz, ft);
        Vec3d s(Rgb(fs[0], fs[1], fs[2]));
        Vec3d t(Rgb(ft[0], ft[1], ft[2]));
        if (d < d_first) {
            // Linear fade from the camera (L = 0, T = 1) to the first slice centre.
            const double f = d / d_first;
            s = s * f;
            t = Vec3d(1.0) - (Vec3d(1.0) - t) * f;
        }
        *scatter = s;
        *trans = t;
        return true;
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) {
            // A camera on the ground looking down (physics/ray.h): the ground at the camera.
            if (want_ground && GroundAtCamera(seg) && MaxComponent(atm.ground_albedo) > 0.0) {
                out.ground = Rgb(GroundReflection(camera, sun));
            }
            return out;
        }
        const double r = Length(camera);
        Vec3d L, T(1.0);
        if ((sky_view.data != nullptr || per_query_sky_view_steps > 0) && r <= atm.top_radius) {
            const double mu = ClampCosine(Dot(dir, camera) / r);
            if (!seg.hits_ground) {
                L = SkyView(camera, dir, sun);
                T = Transmittance(r, mu);
            } else {
                // Weight of the sky-view path: 1 beyond the volume, blending
                // from the volume over its last slices (no seam at its end).
                double w = 1.0;
                if (ground_from_ap && AerialPerspective(dir, seg.t_end, &L, &T)) {
                    const double d0 =
                        HillaireApSliceDistance(kHillaireApBlendSlice, ap_metres_per_slice);
                    const double d1 =
                        HillaireApSliceDistance(kHillaireApSize - 1, ap_metres_per_slice);
                    w = Clamp((seg.t_end - d0) / (d1 - d0), 0.0, 1.0);
                }
                if (w > 0.0) {
                    const Vec3d Ls = SkyView(camera, dir, sun);
                    const Vec3d Ts = TransmittanceToGround(r, mu, seg.t_end);
                    L = L * (1.0 - w) + Ls * w;
                    T = T * (1.0 - w) + Ts * w;
                }
            }
        } else {
            Integrate(camera, dir, sun, seg.t_start, seg.t_end, steps, &L, &T);
        }
        out.sky = Rgb(L);
        out.transmittance = Rgb(T);
        if (want_ground && seg.hits_ground && MaxComponent(atm.ground_albedo) > 0.0) {
            out.ground = Rgb(GroundReflection(camera + dir * seg.t_end, sun) * T);
        }
        return out;
    }
};

// The per-frame tables for one camera and sun. Not copyable: the evaluator
// references the tables.
class HillaireFrame : private NonCopyable {
  public:
    HillaireFrame() = default;
    // The evaluator with this frame's tables attached.
    HillaireEvaluator Evaluator() const;
    HillaireEvaluator base;
    Table sky_view, ap_scatter, ap_transmittance;  // empty when not built
};

struct HillaireOptions {
    int steps = 40;                // ray-march steps for cameras outside the atmosphere
    int sky_view_steps = 100;      // per sky-view texel (demo: 30; issue 15)
    int transmittance_steps = 40;  // of the transmittance table
    double ap_km_per_slice = 4.0;  // aerial-perspective depth scale
    int ap_steps_per_slice = 4;
    double segment_offset = 0.5;     // sample position inside a march segment (demo: 0.3)
    bool ground_from_ap = true;      // ground rays from the aerial-perspective volume
    bool sample_with_tables = true;  // sample through sky-view tables (false: march)
};

class HillaireModel : public Model {
  public:
    static const OptionTable<HillaireOptions>& OptionRows();
    explicit HillaireModel(const HillaireOptions& options);
    static ModelInfo StaticInfo();
    const ModelInfo& Info() const override { return info_; }
    // Builds the transmittance and multiple-scattering tables (timed).
    void Prepare(const AtmosphereParameters& atmosphere) override;
    // Builds the frame (sky-view and aerial perspective for the view's camera
    // and sun), then renders through it (not thread-safe: one Render at a time
    // per model). Each table's build time is in the stage log (StageLogScope).
    void Render(const RenderRequest& request, Image* out) const override;
    std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const override;
    bool CanBake() const override { return true; }
    void Bake(const std::string& directory) const override;
    int64_t TableBytes() const override;
    void LoadBaked(const std::string& directory, const AtmosphereParameters& atmosphere) override;

    // Wide channel batches (models/hillaire_wide.h): PrepareWide builds the
    // transmittance and multiple-scattering tables of every batch at once (n
    // channels per texel; `prepare_batch` is not called: the tables are the
    // batches' own, computed together); RenderWide builds the frame's
    // sky-view and aerial-perspective tables with n channels and renders
    // through them; SampleWide answers as Sample.
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;
    // The wide tables of the last PrepareWide (n channels per texel), for tests.
    const Table& wide_transmittance_table() const { return wide_transmittance_; }
    const Table& wide_multiple_scattering_table() const { return wide_multiple_scattering_; }

    // Per-frame work, exposed for benchmarks: the sky-view table for a camera
    // at `camera` and sun `sun` (when inside the atmosphere), and with
    // `with_aerial_perspective` the volume for `camera_frame` at aspect ratio
    // width / height.
    std::unique_ptr<HillaireFrame> BuildFrame(const Camera& camera_frame, const Vec3d& sun,
                                              double aspect,
                                              bool with_aerial_perspective = true) const;
    // Builds only a sky-view table for camera radius r and sun cosine mu_s
    // (sun in the x-z plane), into `table` (192 x 108 x RGB).
    void BuildSkyView(double r, double mu_s, Table* table) const;

    // Evaluator without per-frame tables (ray march everywhere).
    HillaireEvaluator MakeEvaluator() const { return evaluator_; }
    const AtmosphereParameters& atmosphere() const { return evaluator_.atm; }
    const Table& transmittance_table() const { return transmittance_; }
    const Table& multiple_scattering_table() const { return multiple_scattering_; }
    // The two steps of Prepare(), public for benchmarks: the transmittance
    // table for the current atmosphere, then the multiple-scattering table
    // from it.
    void BuildTransmittance();
    // transfer (optional): receives f_ms per texel (HillaireMultipleScatteringStage).
    void BuildMultipleScattering(Table* transfer = nullptr);

  private:
    void Attach();
    // The evaluator the precomputation stages read (the model's tables only).
    HillaireEvaluator StageEvaluator() const;

    ModelInfo info_;
    HillaireOptions options_;
    HillaireEvaluator evaluator_;
    int transmittance_steps_ = 40;
    int sky_view_steps_ = 30;
    int ap_steps_per_slice_ = 4;
    bool sample_with_tables_ = true;
    Table transmittance_, multiple_scattering_;
    // Wide channel batches: batch 0's atmosphere (the common fields), the
    // channels' coefficients and the n-channel tables (empty: not prepared).
    AtmosphereParameters wide_atm_;
    WideCoefficients wide_;
    Table wide_transmittance_, wide_multiple_scattering_;
    mutable ResidentTables resident_;  // the tables' device copies (render/stages.h)
};

}  // namespace atmos
