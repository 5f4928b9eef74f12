// The reference's hybrid estimator (`estimator=hybrid`, the default): order 1
// by an adaptive quadrature on a per-pixel table of the view ray, orders >= 2
// by paths whose first vertex is drawn from the same table, the sun's
// transmittance from a checked table (reference.h, docs/models/reference.md).
#pragma once

#include <stdint.h>

#include "models/reference_baseline.h"

namespace atmos {

// The view ray's per-pixel table of the hybrid estimator: about this many
// intervals in all, at most kHybridMaxNodes nodes.
constexpr int kHybridViewIntervals = 96;
constexpr int kHybridMaxNodes = 128;
// The table's capacity: adaptive refinement (BuildViewTable) adds nodes where
// the initial ones do not resolve the ray, up to this many in all, halving a
// panel at most kMaxViewLevels times.
constexpr int kHybridNodeCapacity = 256;
constexpr int kMaxViewLevels = 20;
// BuildViewTable's acceptance of a panel: Simpson against its halves within
// 15 (kViewTauAbs + kViewTauRel dtau), the trapezoid within kViewGrossAbs +
// dtau / 2, at most kViewMaxStep of view or sun optical depth across it (all
// relaxed by exp(tau0 / 5) where the light is already attenuated by tau0).
constexpr double kViewTauAbs = 1e-5;
constexpr double kViewTauRel = 1e-4;
constexpr double kViewGrossAbs = 1e-4;
constexpr double kViewMaxStep = 0.5;
// The most next-event comb points per continuation segment.
constexpr int kMaxNeeComb = 8;

// A point of the view ray drawn by the mass of a view table (the hybrid's
// and the hero paths' nodes: .t, .cdf, cdf ascending, `mass` the last cdf):
// the interval [nodes[lo].t, nodes[lo + 1].t] by its share of the mass
// (binary search), then a point uniform within it; two uniforms drawn. False
// for an interval without mass or width (the caller skips the sample).
struct ViewIntervalPoint {
    int lo = 0;
    double t = 0.0;
    double p_interval = 0.0;  // the interval's probability
    double width = 0.0;       // its length (m)
};
template <typename Node>
ATMOS_HD inline bool DrawViewInterval(const Node* nodes, int count, double mass, Rng& rng,
                                      ViewIntervalPoint* out) {
    const double u = rng.Uniform() * mass;
    // nodes[lo].cdf <= u < nodes[hi].cdf
    const int lo = BisectInterval(count, [&](int i) { return nodes[i].cdf <= u; });
    const int hi = Min(lo + 1, count - 1);
    const double width = nodes[hi].t - nodes[lo].t;
    const double p_interval = (nodes[hi].cdf - nodes[lo].cdf) / mass;
    if (!(p_interval > 0.0) || !(width > 0.0)) return false;
    out->lo = lo;
    out->t = nodes[lo].t + rng.Uniform() * width;
    out->p_interval = p_interval;
    out->width = width;
    return true;
}

struct ReferenceHybrid : ReferenceBaseline {
    // kHybrid: the sun's transmittance table and the factor (>= 1) on the
    // continuation segments' majorants.
    SunTransmittanceTable sun_table;
    double continuation_majorant_scale = 4.0;
    // kHybrid: uniform next-event points per continuation segment (0: none),
    // and the first direction's sun lobe (probability, Henyey-Greenstein g).
    int nee_comb = 0;
    double sun_lobe = 0.0;
    double sun_lobe_g = 0.8;
    // kHybrid renders: order 1 of every pixel (sky + ground, per unit
    // irradiance; width x height x 3, texel (key % width, key / width)),
    // computed once per request and reused by every pass (order1_cached),
    // which then skips the view table's sun transmittances and Simpson sums.
    TableView order1_table;
    bool order1_cached = false;

    // ---- the hybrid estimator (ReferenceEstimator::kHybrid) ----
    //
    // The radiance of a view segment [0, L] is order 1 (light scattered once,
    // toward the camera, from the sun) plus orders >= 2. Order 1 is
    //   L1 = int_0^L T(t) [sigma_R(t) P_R(nu) + sigma_M(t) P_M(nu)] T_sun(x(t)) dt
    //        (+ T(L) rho/pi cos_s T_sun(x(L)) on a reflecting ground),
    // computed deterministically by composite Simpson on a per-pixel table of
    // nodes (uniform within pieces split at the planet's shadow cylinder, so
    // T_sun's jump there is a piece boundary). Orders >= 2 are one Monte Carlo
    // path per sample: its first real vertex is drawn from the same table,
    // in the volume with pdf ~ mean_c(sigma_s,c T_c) (interval by its
    // trapezoid mass, then uniform in it; the weight uses sigma_s and T at the
    // drawn point exactly: T by the table's optical depth at the interval's
    // start plus the trapezoid of sigma_t over the partial interval), or on the
    // ground (probability P_g, below); every path thus scatters for real at
    // least once, and its next-event estimates start at order 2. The path then
    // continues by spectral tracking against the shells' majorants times
    // continuation_majorant_scale (next-event estimation at every tentative
    // collision: a looser majorant means more, cheaper estimates), the sun's
    // transmittance of every estimate from sun_table.
    struct ViewNode {
        double t;
        Vec3d tau;      // view optical depth from the segment's start
        Vec3d sigma_t;  // extinction at the node
        double cdf;     // first-vertex mass of the intervals before this node
        // Build-time only: dt/du, Rayleigh and Mie densities, sun transmittance.
        double jac, rho_r, rho_m;
        Vec3d sun_t;
        // The Rayleigh, Mie and absorption densities at the node and their
        // columns from the segment's start (m), by the rules of tau (which is
        // linear in them: the hero paths' optical depth at any wavelength).
        Vec3d rho, column;
    };

    // A monotonic piece [a, b] of the view segment: t = a + span u^2 from its
    // low end (b - span (1 - u)^2 when the low end is b), n initial intervals.
    struct ViewPiece {
        double a, b, span;
        bool low_at_a;
        int n;
    };
    // A Simpson panel waiting to be tested: nodes j0, j0 + 1, j0 + 2 of
    // n 2^level intervals (its start is the table's last node).
    struct ViewPanel {
        int level;
        int64_t j0;
        ViewNode mid, end;
    };

    // The node u = j / denom of a piece (the sun's transmittance only with_sun).
    ATMOS_HD ViewNode MakeViewNode(const Vec3d& start, const Vec3d& dir, const Vec3d& sun,
                                   const ViewPiece& pc, int64_t j, int64_t denom,
                                   bool with_sun) const {
        const double u = static_cast<double>(j) / static_cast<double>(denom);
        double t, jac;
        if (pc.low_at_a) {
            t = pc.a + pc.span * u * u;
            jac = 2.0 * pc.span * u;
        } else {
            t = pc.b - pc.span * (1.0 - u) * (1.0 - u);
            jac = 2.0 * pc.span * (1.0 - u);
        }
        if (j == denom) t = pc.b;
        const Densities d = GetDensities(atm, Length(start + dir * t) - atm.bottom_radius);
        ViewNode node;
        node.t = t;
        node.tau = Vec3d(0.0);
        node.sigma_t = Extinction(atm, d);
        node.cdf = 0.0;
        node.jac = jac;
        node.rho_r = d.rayleigh;
        node.rho_m = d.mie;
        node.rho = Vec3d(d.rayleigh, d.mie, d.absorption);
        node.column = Vec3d(0.0);
        // The sun's transmittance just inside the piece at its ends (it
        // jumps at a shadow crossing: each piece takes its side).
        const double ts = j == 0 ? t + 1e-7 * pc.span : (j == denom ? t - 1e-7 * pc.span : t);
        node.sun_t = with_sun ? SunTransmittanceAt(start + dir * ts, sun) : Vec3d(0.0);
        return node;
    }

    ATMOS_HD Vec3d SunTransmittanceAt(const Vec3d& p, const Vec3d& sun) const {
        const double r = Length(p);
        const double mu = ClampCosine(Dot(p, sun) / r);
        if (sun_table.direct) {
            if (RayIntersectsGround(r, mu, atm.bottom_radius)) return Vec3d(0.0);
            const double rc = Min(r, atm.top_radius);
            return Exp(-AdaptiveOpticalDepth(
                atm, p * (rc / r), sun, DistanceToTopAtmosphereBoundary(rc, mu, atm.top_radius)));
        }
        return sun_table.Lookup(r, mu);
    }

    // Where p + t dir crosses the planet's shadow cylinder (radius bottom,
    // axis -sun) on its night side, for t in (0, length): up to 2, sorted.
    ATMOS_HD int ShadowCrossings(const Vec3d& p, const Vec3d& dir, const Vec3d& sun, double length,
                                 double* out) const {
        const Vec3d pp = p - sun * Dot(p, sun);
        const Vec3d dp = dir - sun * Dot(dir, sun);
        const double a = Dot(dp, dp);
        const double b = Dot(pp, dp);
        const double c = Dot(pp, pp) - atm.bottom_radius * atm.bottom_radius;
        const double disc = b * b - a * c;
        int n = 0;
        if (a <= 0.0 || disc <= 0.0) return 0;
        const double q = Sqrt(disc);
        const double roots[2] = {(-b - q) / a, (-b + q) / a};
        for (double t : roots) {
            if (t > 0.0 && t < length && Dot(p + dir * t, sun) < 0.0) out[n++] = t;
        }
        return n;
    }

    // Builds the table (returns the node count) and order 1 of the volume.
    //
    // Pieces: the segment is cut at its lowest point (the tangent point, where
    // the altitude turns) and where it crosses the planet's shadow, so that in
    // each piece the altitude is monotonic and the sun's transmittance smooth.
    // In each piece t = a + (b - a) u^2 from its low end (u uniform, n_k even
    // intervals, about kHybridViewIntervals in all by length): nodes are dense
    // where the air is. Integrals over t are Simpson's rule in u with the
    // Jacobian dt/du (the integrand times it is smooth, also at u = 0); the
    // optical depth at odd nodes by the 3-point rule h/12 (5 g0 + 8 g1 - g2).
    //
    // Adaptive panels (issue 32): each Simpson panel (two intervals) is
    // accepted only where it resolves the ray, else halved in u (depth first,
    // in the order of t, so the optical depth at a panel's start is known):
    // its optical depth must agree with the two half panels' (|S2 - S1| <= 15
    // (1e-6 + 1e-4 S2), the adaptive Simpson test: a density whose scale is
    // far below the piece's length, e.g. an 8 km scale height on a 1e9 m
    // shell, is found and resolved), and its optical depth and the change of
    // the sun's optical depth across it must stay below 0.5 (Simpson on
    // exp(-tau) is then good to ~1e-4 of the panel). Where the light is
    // already attenuated (the least attenuated channel's tau0 at the panel's
    // start) the bounds grow by exp(tau0 / 5), which equidistributes the
    // error exp(-tau0) dtau^5 over the ray: an optically thick ray (tau 277
    // in issue 32's slab) needs ~20 panels near the camera instead of
    // resolving all of it. At most kHybridNodeCapacity nodes and
    // kMaxViewLevels halvings; panels the initial placement resolves are
    // unchanged (Earth's views: the same nodes and sums as before).
    // with_order1 false: the table alone (no sun transmittances, *order1 0).
    ATMOS_HD int BuildViewTable(const Vec3d& start, const Vec3d& dir, const Vec3d& sun,
                                double length, ViewNode* nodes, Vec3d* order1,
                                bool with_order1 = true) const {
        double cuts[6];
        int nc = 0;
        cuts[nc++] = 0.0;
        const double t_low = -Dot(start, dir);
        if (t_low > 1e-6 * length && t_low < (1.0 - 1e-6) * length) cuts[nc++] = t_low;
        double crossings[2];
        const int ns = ShadowCrossings(start, dir, sun, length, crossings);
        for (int i = 0; i < ns; ++i) {
            // Insert sorted (at most 4 cuts so far).
            int j = nc++;
            while (j > 0 && cuts[j - 1] > crossings[i]) {
                cuts[j] = cuts[j - 1];
                --j;
            }
            cuts[j] = crossings[i];
        }
        cuts[nc++] = length;
        const double nu = Dot(dir, sun);
        const double p_r = RayleighPhase(nu);
        const double p_m = MiePhase(atm, nu);
        // The initial intervals per piece (about kHybridViewIntervals in all,
        // at most kHybridMaxNodes nodes); refinement may add up to the capacity.
        ViewPiece pieces[5];
        int count = 0;
        for (int k = 0; k + 1 < nc; ++k) {
            ViewPiece& pc = pieces[k];
            pc.a = cuts[k];
            pc.b = cuts[k + 1];
            pc.span = pc.b - pc.a;
            int n = static_cast<int>(kHybridViewIntervals * pc.span / length + 0.5);
            n = Max(4, n + (n & 1));
            n = Min(n, kHybridMaxNodes - 1 - count - 4 * (nc - 2 - k));
            n -= n & 1;
            pc.n = n;
            pc.low_at_a = Length(start + dir * pc.a) <= Length(start + dir * pc.b);
            count += k == 0 ? n + 1 : n;
        }
        int spare = kHybridNodeCapacity - count;  // nodes refinement may still add
        Vec3d o1;
        nodes[0] = MakeViewNode(start, dir, sun, pieces[0], 0, pieces[0].n, with_order1);
        nodes[0].tau = Vec3d(0.0);
        nodes[0].cdf = 0.0;
        count = 1;
        // Adds node `cur`'s first-vertex mass after node `prev`.
        auto mass = [&](const ViewNode& prev, ViewNode* cur) {
            const Vec3d sigma_s_prev =
                atm.rayleigh_scattering * prev.rho_r + atm.mie_scattering * prev.rho_m;
            const Vec3d sigma_s =
                atm.rayleigh_scattering * cur->rho_r + atm.mie_scattering * cur->rho_m;
            const double g0 = Dot(sigma_s_prev * Exp(-prev.tau), Vec3d(1.0 / 3.0));
            const double g1 = Dot(sigma_s * Exp(-cur->tau), Vec3d(1.0 / 3.0));
            cur->cdf = prev.cdf + 0.5 * (cur->t - prev.t) * (g0 + g1);
        };
        // Order 1's integrand at a node (times its Jacobian and weight later).
        auto source = [&](const ViewNode& node, const Vec3d& sun_t) {
            return (atm.rayleigh_scattering * (node.rho_r * p_r) +
                    atm.mie_scattering * (node.rho_m * p_m)) *
                   Exp(-node.tau) * sun_t;
        };
        for (int k = 0; k + 1 < nc; ++k) {
            const ViewPiece& pc = pieces[k];
            const double h0 = 1.0 / pc.n;
            // The piece's u = 0 node is the previous piece's last node, except
            // for its sun transmittance (the other side of a cut) and dt/du.
            double start_jac = pc.low_at_a ? 0.0 : 2.0 * (cuts[k + 1] - cuts[k]);
            Vec3d start_sun =
                k == 0 || !with_order1
                    ? nodes[0].sun_t
                    : SunTransmittanceAt(start + dir * (cuts[k] + 1e-7 * (cuts[k + 1] - cuts[k])),
                                         sun);
            double pending_h = 0.0;  // the start node's weight from the panel before it
            for (int p = 0; p < pc.n / 2; ++p) {
                ViewPanel stack[kMaxViewLevels + 2];
                int top = 0;
                stack[top].level = 0;
                stack[top].j0 = 2 * p;
                stack[top].mid = MakeViewNode(start, dir, sun, pc, 2 * p + 1, pc.n, with_order1);
                stack[top].end = MakeViewNode(start, dir, sun, pc, 2 * p + 2, pc.n, with_order1);
                ++top;
                while (top > 0) {
                    const ViewPanel e = stack[--top];
                    const int64_t denom = static_cast<int64_t>(pc.n) << e.level;
                    const double h = h0 / static_cast<double>(int64_t(1) << e.level);
                    const ViewNode& s = nodes[count - 1];
                    if (e.level < kMaxViewLevels && spare >= 2) {
                        ViewNode q1 =
                            MakeViewNode(start, dir, sun, pc, 2 * e.j0 + 1, 2 * denom, false);
                        ViewNode q3 =
                            MakeViewNode(start, dir, sun, pc, 2 * e.j0 + 3, 2 * denom, false);
                        const Vec3d g0 = s.sigma_t * start_jac, g2 = e.mid.sigma_t * e.mid.jac;
                        const Vec3d g4 = e.end.sigma_t * e.end.jac;
                        const Vec3d s1 = (g0 + g2 * 4.0 + g4) * (h / 3.0);
                        const Vec3d s2 = (g0 + q1.sigma_t * (4.0 * q1.jac) + g2 * 2.0 +
                                          q3.sigma_t * (4.0 * q3.jac) + g4) *
                                         (h / 6.0);
                        const double dtau = MaxComponent(s2);
                        const double err = MaxComponent(Max(s2 - s1, s1 - s2));
                        const double relax = exp(Min(MinComponent(s.tau), 60.0) / 5.0);
                        // The trapezoid in t on the same five points: far from
                        // Simpson's where a density concentrated near u = 0
                        // (where dt/du vanishes) slipped between the points.
                        const Vec3d trap = ((s.sigma_t + q1.sigma_t) * (q1.t - s.t) +
                                            (q1.sigma_t + e.mid.sigma_t) * (e.mid.t - q1.t) +
                                            (e.mid.sigma_t + q3.sigma_t) * (q3.t - e.mid.t) +
                                            (q3.sigma_t + e.end.sigma_t) * (e.end.t - q3.t)) *
                                           0.5;
                        const double gross = MaxComponent(Max(trap - s2, s2 - trap));
                        bool split = err > 15.0 * (kViewTauAbs + kViewTauRel * dtau) * relax ||
                                     dtau > kViewMaxStep * relax ||
                                     gross > (kViewGrossAbs + 0.5 * dtau) * relax;
                        // The sun's optical depth across the panel, from the
                        // geometry alone (so that the table is the same with
                        // or without order 1, as the order-1 cache needs):
                        // sigma_t |dr| / |mu_s| (plane-parallel; |mu_s| >= 0.05).
                        if (!split) {
                            const Vec3d xs = start + dir * s.t, xm = start + dir * e.mid.t;
                            const double dr = Abs(Length(start + dir * e.end.t) - Length(xs));
                            const double mu_s = Dot(xm, sun) / Length(xm);
                            const double sigma =
                                MaxComponent(Max(s.sigma_t, Max(e.mid.sigma_t, e.end.sigma_t)));
                            split = sigma * dr / Max(Abs(mu_s), 0.05) > kViewMaxStep * relax;
                        }
                        if (split) {
                            if (with_order1) {
                                q1.sun_t = SunTransmittanceAt(start + dir * q1.t, sun);
                                q3.sun_t = SunTransmittanceAt(start + dir * q3.t, sun);
                            }
                            spare -= 2;
                            // Right half below, left half on top (done first).
                            stack[top].level = e.level + 1;
                            stack[top].j0 = 2 * e.j0 + 2;
                            stack[top].mid = q3;
                            stack[top].end = e.end;
                            ++top;
                            stack[top].level = e.level + 1;
                            stack[top].j0 = 2 * e.j0;
                            stack[top].mid = q1;
                            stack[top].end = e.mid;
                            ++top;
                            continue;
                        }
                    }
                    // Accept the panel: its middle and end nodes.
                    ViewNode& mid = nodes[count];
                    ViewNode& end = nodes[count + 1];
                    mid = e.mid;
                    end = e.end;
                    mid.tau = s.tau + (s.sigma_t * (5.0 * start_jac) +
                                       mid.sigma_t * (8.0 * mid.jac) - end.sigma_t * end.jac) *
                                          (h / 12.0);
                    end.tau = s.tau + (s.sigma_t * start_jac + mid.sigma_t * (4.0 * mid.jac) +
                                       end.sigma_t * end.jac) *
                                          (h / 3.0);
                    mid.column = s.column + (s.rho * (5.0 * start_jac) + mid.rho * (8.0 * mid.jac) -
                                             end.rho * end.jac) *
                                                (h / 12.0);
                    end.column = s.column + (s.rho * start_jac + mid.rho * (4.0 * mid.jac) +
                                             end.rho * end.jac) *
                                                (h / 3.0);
                    // Optical depth never decreases (the 3-point rule can
                    // undershoot where the extinction rises steeply).
                    mid.tau = Max(mid.tau, s.tau);
                    end.tau = Max(end.tau, mid.tau);
                    mid.column = Max(mid.column, s.column);
                    end.column = Max(end.column, mid.column);
                    mass(s, &mid);
                    mass(mid, &end);
                    if (with_order1) {
                        o1 += source(s, start_sun) * (start_jac * (pending_h + h) / 3.0);
                        o1 += source(mid, mid.sun_t) * (mid.jac * 4.0 * h / 3.0);
                    }
                    count += 2;
                    start_jac = end.jac;
                    start_sun = end.sun_t;
                    pending_h = h;
                }
            }
            if (with_order1) {
                const ViewNode& last = nodes[count - 1];
                o1 += source(last, last.sun_t) * (last.jac * pending_h / 3.0);
            }
        }
        *order1 = o1;
        return count;
    }

    // A segment of a continued path (HybridContinue, ReferenceHero): its
    // origin, the distance moved along it, its length, and the next-event
    // comb's intensity and points (sorted; `next` the first not yet passed).
    struct CombSegment {
        Vec3d origin;
        double travelled = 0.0, length = 0.0, intensity = 0.0;
        double t[kMaxNeeComb];
        int n = 0, next = 0;
    };

    // Starts a segment at p along dir. The comb only where the sun is below
    // the origin's horizon (twilight: the lit air is thin and far); a choice by
    // the segment's origin alone, so both strategies stay unbiased. `length`
    // is set only with a comb (without one nothing reads it).
    ATMOS_HD void BeginCombSegment(const Vec3d& p, const Vec3d& dir, const Vec3d& sun, Rng& rng,
                                   CombSegment* s) const {
        s->origin = p;
        s->travelled = 0.0;
        s->n = s->next = 0;
        s->intensity = 0.0;
        if (nee_comb > 0 && Dot(p, sun) < 0.0) {
            const double r = Length(p);
            const double mu = ClampCosine(Dot(p, dir) / r);
            s->length = RayIntersectsGround(r, mu, atm.bottom_radius)
                            ? DistanceToBottomAtmosphereBoundary(r, mu, atm.bottom_radius)
                            : DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
            if (s->length > 0.0) {
                s->n = Min(nee_comb, kMaxNeeComb);
                s->intensity = s->n / s->length;
                for (int j = 0; j < s->n; ++j) s->t[j] = s->length * (j + rng.Uniform()) / s->n;
            }
        }
    }

    // Continues a path from a real vertex (direction already sampled): adds
    // every next-event estimate (orders >= order + 1) to *radiance.
    //
    // Next-event estimates on each segment (from a real vertex to the ground
    // or space) come from two point sets, combined by multiple importance
    // sampling (balance heuristic): the tentative collisions of the tracking
    // (intensity sigma_bar(t), the continuation majorant; weight w, an
    // unbiased estimate of the segment's transmittance T(t)), and a comb of
    // `nee_comb` stratified uniform points over the segment's geometric length
    // d (intensity n / d), each scored with the path's weight w where the path
    // reached it (E[w 1(reached t)] = T(t): spectral tracking's transmittance
    // estimate), nothing beyond the segment's real collision. Both score
    // w sigma_s P T_sun / (sigma_bar(t) + n / d), so their sum estimates
    // int T sigma_s P T_sun dt without bias; the comb samples the thin, lit
    // air where sigma_bar is small and the collisions rare (twilight).
    ATMOS_HD void HybridContinue(Vec3d p, Vec3d dir, Vec3d w, int order, const Vec3d& sun, Rng& rng,
                                 Vec3d* radiance) const {
        int shell = shells.ShellOf(Length(p));
        const double k = continuation_majorant_scale;
        // The segment being tracked, with its next-event comb.
        CombSegment seg;
        bool new_segment = true;
        for (int guard = 0; guard < 1000000; ++guard) {
            if (new_segment) {
                new_segment = false;
                BeginCombSegment(p, dir, sun, rng, &seg);
            }
            const Step step = Track(&p, dir, &shell, rng, k, &seg.travelled);
            const bool light = max_order == 0 || order < max_order;
            // The comb's points the path has passed (all, once it leaves the segment).
            const double reached = step == Step::kCollision ? seg.travelled : seg.length;
            for (; seg.next < seg.n && seg.t[seg.next] <= reached; ++seg.next) {
                if (light)
                    *radiance += w * CombEstimate(seg.origin + dir * seg.t[seg.next], dir, sun,
                                                  seg.intensity);
            }
            if (step == Step::kEscaped) break;
            if (step == Step::kGround) {
                ++order;
                if (max_order > 0 && order > max_order) break;
                if (MaxComponent(atm.ground_albedo) <= 0.0) break;
                const Vec3d n = Normalize(p);
                const double cos_sun = Dot(n, sun);
                if (cos_sun > 0.0) {
                    *radiance +=
                        w * atm.ground_albedo * (cos_sun / kPi) * SunTransmittanceAt(p, sun);
                }
                dir = MakeDirection(n, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                w = w * atm.ground_albedo;
                new_segment = true;
            } else {
                const Collision c = CollisionAt(p, k * shells.majorant[shell], w);
                if (!(c.total > 0.0)) break;
                // Next-event estimate with the expected value of the event
                // choice (as TracePath), MIS-weighted against the comb.
                if (light) {
                    const Vec3d scatter = InScatter(c.sigma_r, c.sigma_m, Dot(dir, sun));
                    if (MaxComponent(w * scatter) > 0.0) {
                        *radiance += w * scatter * (1.0 / (c.sigma_bar + seg.intensity)) *
                                     SunTransmittanceAt(p, sun);
                    }
                }
                const Event event = ChooseEvent(c, rng, &w);
                if (event == Event::kNull) continue;
                ++order;
                if (max_order > 0 && order >= max_order) break;
                dir = SamplePhaseDirection(dir, event == Event::kRayleigh, rng, &w);
                new_segment = true;
            }
            if (order >= 3) {
                const double q = RouletteSurvival(order, MaxComponent(w));
                if (rng.Uniform() >= q) break;
                w = w * (1.0 / q);
            }
        }
    }

    // A comb point's next-event estimate per unit throughput: sigma_s P T_sun
    // over the sum of both strategies' intensities there.
    ATMOS_HD Vec3d CombEstimate(const Vec3d& q, const Vec3d& dir, const Vec3d& sun,
                                double comb) const {
        const double r = Length(q);
        const Densities d = GetDensities(atm, r - atm.bottom_radius);
        const Vec3d scatter = InScatter(atm.rayleigh_scattering * d.rayleigh,
                                        atm.mie_scattering * d.mie, Dot(dir, sun));
        if (!(MaxComponent(scatter) > 0.0)) return Vec3d(0.0);
        const double sigma_bar = continuation_majorant_scale * shells.majorant[shells.ShellOf(r)];
        return scatter * (1.0 / (sigma_bar + comb)) * SunTransmittanceAt(q, sun);
    }

    // The first vertex's continuation direction: the phase function, or, at
    // a vertex x with the sun below its horizon (twilight), with probability
    // sun_lobe a Henyey-Greenstein lobe (sun_lobe_g) around the sun (one-
    // sample MIS, balance heuristic: w *= phase / (mixture pdf)).
    ATMOS_HD Vec3d SampleFirstDirection(const Vec3d& x, const Vec3d& dir, bool rayleigh,
                                        const Vec3d& sun, Rng& rng, Vec3d* w) const {
        if (!(sun_lobe > 0.0) || Dot(x, sun) >= 0.0) {
            return SamplePhaseDirection(dir, rayleigh, rng, w);
        }
        Vec3d next;
        if (rng.Uniform() < sun_lobe) {
            next = MakeDirection(sun, SampleHenyeyGreensteinCosine(sun_lobe_g, rng.Uniform()),
                                 rng.Uniform());
        } else {
            const double xi = rng.Uniform();
            next = MakeDirection(
                dir, rayleigh ? SampleRayleighCosine(xi) : SampleMiePhaseCosine(atm, xi),
                rng.Uniform());
        }
        const double mu = Dot(dir, next);
        const double phase = rayleigh ? RayleighPhase(mu) : MiePhase(atm, mu);
        const double p_phase = rayleigh ? phase : MiePhaseSamplingPdf(atm, mu);
        const double pdf = (1.0 - sun_lobe) * p_phase +
                           sun_lobe * HenyeyGreensteinPhase(sun_lobe_g, Dot(next, sun));
        *w = *w * (phase / pdf);
        return next;
    }

    // The hybrid estimate of one view segment from `start` (length 0 with
    // hits_ground: a camera on the ground looking down).
    ATMOS_HD void EvaluateHybrid(const Vec3d& start, const Vec3d& dir, const Vec3d& sun,
                                 double length, bool hits_ground, uint64_t key, Vec3d* sky,
                                 Vec3d* ground, Vec3d* tau_out) const {
        ViewNode nodes[kHybridNodeCapacity];
        Vec3d order1;
        int count = 1;
        if (length > 0.0) {
            count = BuildViewTable(start, dir, sun, length, nodes, &order1, !order1_cached);
        } else {
            nodes[0] = {0.0, Vec3d(0.0), Vec3d(0.0), 0.0,        0.0,
                        0.0, 0.0,        Vec3d(0.0), Vec3d(0.0), Vec3d(0.0)};
        }
        const Vec3d tau_end = nodes[count - 1].tau;
        *tau_out = tau_end;
        const double mass = nodes[count - 1].cdf;  // int mean_c(sigma_s T) dt
        const bool reflective = hits_ground && MaxComponent(atm.ground_albedo) > 0.0;
        const Vec3d t_end = Exp(-tau_end);
        const Vec3d ground_point = start + dir * length;
        const Vec3d normal = Normalize(ground_point);
        // Order 1 (deterministic; sky and ground together when cached).
        if (order1_cached) {
            const int w = order1_table.width;
            const Vec4f o = order1_table.Fetch(static_cast<int>(key % static_cast<uint64_t>(w)),
                                               static_cast<int>(key / static_cast<uint64_t>(w)));
            *sky += Vec3d(o.x, o.y, o.z) * static_cast<double>(sample_count);
        } else {
            *sky += order1 * static_cast<double>(sample_count);
        }
        if (reflective && !order1_cached) {
            const double cos_sun = Dot(normal, sun);
            if (cos_sun > 0.0) {
                *ground += t_end * atm.ground_albedo * (cos_sun / kPi) *
                           SunTransmittanceAt(ground_point, sun) *
                           static_cast<double>(sample_count);
            }
        }
        if (max_order == 1) return;
        // The first real vertex: ground with probability p_ground, else the volume.
        const double ground_mass =
            reflective ? Dot(t_end * atm.ground_albedo, Vec3d(1.0 / 3.0)) : 0.0;
        double p_ground = 0.0;
        if (ground_mass > 0.0) {
            p_ground = mass > 0.0 ? Clamp(ground_mass / (ground_mass + mass), 0.05, 0.95) : 1.0;
        }
        if (!(mass > 0.0) && p_ground <= 0.0) return;
        for (int64_t s = 0; s < sample_count; ++s) {
            Rng rng(seed, key, static_cast<uint64_t>(sample_begin + s));
            if (rng.Uniform() < p_ground) {
                const Vec3d w = t_end * atm.ground_albedo * (1.0 / p_ground);
                const Vec3d next = MakeDirection(
                    normal, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                // A hair above the ground so the first track starts inside.
                HybridContinue(normal * (atm.bottom_radius + 1e-3), next, w, 1, sun, rng, ground);
                continue;
            }
            // Interval by its mass, then uniform.
            ViewIntervalPoint v;
            if (!DrawViewInterval(nodes, count, mass, rng, &v)) continue;
            const ViewNode& a = nodes[v.lo];
            const double t = v.t;
            const Vec3d x = start + dir * t;
            const Densities d = GetDensities(atm, Length(x) - atm.bottom_radius);
            const Vec3d sigma_t = Extinction(atm, d);
            const Vec3d trans = Exp(-(a.tau + (a.sigma_t + sigma_t) * (0.5 * (t - a.t))));
            const double pdf = (1.0 - p_ground) * v.p_interval / v.width;
            const Vec3d w0 = trans * (1.0 / pdf);
            const Vec3d sigma_r = atm.rayleigh_scattering * d.rayleigh;
            const Vec3d sigma_m = atm.mie_scattering * d.mie;
            const double a_r = Dot(w0, sigma_r), a_m = Dot(w0, sigma_m);
            if (!(a_r + a_m > 0.0)) continue;
            const bool rayleigh = rng.Uniform() * (a_r + a_m) < a_r;
            Vec3d w =
                w0 * (rayleigh ? sigma_r * ((a_r + a_m) / a_r) : sigma_m * ((a_r + a_m) / a_m));
            const Vec3d next = SampleFirstDirection(x, dir, rayleigh, sun, rng, &w);
            HybridContinue(x, next, w, 1, sun, rng, sky);
        }
    }
};

}  // namespace atmos
