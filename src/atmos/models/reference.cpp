#include "models/reference.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "render/render.h"

namespace atmos {

namespace {

// Maximum of one layer's unclamped density over [h0, h1]: the end points and
// the critical point of a e^(s h) + l h + c (where a s e^(s h) = -l).
double MaxLayerDensity(const DensityProfileLayer& layer, double h0, double h1) {
    auto f = [&](double h) {
        return layer.exp_term * std::exp(layer.exp_scale * h) + layer.linear_term * h +
               layer.constant_term;
    };
    double m = std::max(f(h0), f(h1));
    const double as = layer.exp_term * layer.exp_scale;
    if (as != 0.0 && layer.exp_scale != 0.0) {
        const double ratio = -layer.linear_term / as;
        if (ratio > 0.0) {
            const double h = std::log(ratio) / layer.exp_scale;
            if (h > h0 && h < h1) m = std::max(m, f(h));
        }
    }
    return m;
}

}  // namespace

double MaxProfileDensity(const DensityProfile& profile, double h0, double h1) {
    const double w = profile.layers[0].width;
    double m = 0.0;
    if (h0 < w) m = std::max(m, MaxLayerDensity(profile.layers[0], h0, std::min(h1, w)));
    if (h1 >= w) m = std::max(m, MaxLayerDensity(profile.layers[1], std::max(h0, w), h1));
    return std::clamp(m, 0.0, 1.0);
}

MajorantShells BuildMajorantShells(const AtmosphereParameters& atm, int count) {
    return BuildMajorantShells(atm, count, {});
}

MajorantShells BuildMajorantShells(const AtmosphereParameters& atm, int count,
                                   const std::vector<HeroSpectrum>& extra) {
    MajorantShells shells;
    shells.count = std::clamp(count, 1, kMaxReferenceShells);
    const double delta = atm.top_radius - atm.bottom_radius;
    for (int k = 0; k <= shells.count; ++k) {
        const double x = static_cast<double>(k) / shells.count;
        shells.radius[k] = atm.bottom_radius + delta * x * x;
    }
    shells.radius[shells.count] = atm.top_radius;
    for (int k = 0; k < shells.count; ++k) {
        const double h0 = shells.radius[k] - atm.bottom_radius;
        const double h1 = shells.radius[k + 1] - atm.bottom_radius;
        const double mr = MaxProfileDensity(atm.rayleigh_density, h0, h1);
        const double mm = MaxProfileDensity(atm.mie_density, h0, h1);
        const double mo = MaxProfileDensity(atm.absorption_density, h0, h1);
        double bar = 0.0;
        for (int c = 0; c < 3; ++c) {
            bar = std::max(bar, atm.rayleigh_scattering[c] * mr + atm.mie_extinction[c] * mm +
                                    atm.absorption_extinction[c] * mo);
        }
        for (const HeroSpectrum& g : extra) {
            for (int c = 0; c < g.count; ++c) {
                bar = std::max(
                    bar, g.rayleigh[c] * mr + g.mie_extinction[c] * mm + g.absorption[c] * mo);
            }
        }
        // A hair above the exact maximum so rounding never makes sigma_n < 0.
        shells.majorant[k] = bar * (1.0 + 1e-9);
    }
    return shells;
}

namespace {

// The Rayleigh, Mie and absorption columns (m) from (r, mu) to the top boundary
// by composite Simpson with `intervals` (even) intervals.
Vec3d SunColumnQuadrature(const AtmosphereParameters& atm, double r, double mu, int intervals) {
    intervals += intervals & 1;
    const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
    const double h = d / intervals;
    Vec3d sum;
    for (int i = 0; i <= intervals; ++i) {
        const double t = i * h;
        const double ri = std::sqrt(std::max(r * r + 2.0 * r * mu * t + t * t, 0.0));
        const double w = (i == 0 || i == intervals) ? 1.0 : ((i & 1) ? 4.0 : 2.0);
        const Densities density = GetDensities(atm, ri - atm.bottom_radius);
        sum += Vec3d(density.rayleigh, density.mie, density.absorption) * w;
    }
    return sum * (h / 3.0);
}

}  // namespace

Vec3d SunOpticalDepthQuadrature(const AtmosphereParameters& atm, double r, double mu,
                                int intervals) {
    const Vec3d c = SunColumnQuadrature(atm, r, mu, intervals);
    return atm.rayleigh_scattering * c.x + atm.mie_extinction * c.y +
           atm.absorption_extinction * c.z;
}

Table BuildSunColumnTable(const AtmosphereParameters& atm, int mu_size, int r_size, int intervals) {
    Table table(mu_size, r_size, 1, 3);
    const double bottom = atm.bottom_radius, top = atm.top_radius;
    const double H = std::sqrt(top * top - bottom * bottom);
    ParallelFor(r_size, 1, [&](int64_t j) {
        const double x_r = static_cast<double>(j) / (r_size - 1);
        const double rho = x_r * H;
        const double r = std::sqrt(rho * rho + bottom * bottom);
        const double d_min = top - r, d_max = rho + H;
        for (int i = 0; i < mu_size; ++i) {
            const double x_mu = static_cast<double>(i) / (mu_size - 1);
            const double d = d_min + x_mu * (d_max - d_min);
            const double mu =
                d == 0.0 ? 1.0 : std::clamp((H * H - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
            const Vec3d column = SunColumnQuadrature(atm, r, mu, intervals);
            float* texel = table.Texel(i, static_cast<int>(j));
            for (int c = 0; c < 3; ++c) texel[c] = static_cast<float>(column[c]);
        }
    });
    return table;
}

bool SunTableResolves(const SunTransmittanceTable& table, const AtmosphereParameters& atm,
                      double* worst) {
    constexpr int kN = 64;
    const double delta = atm.top_radius - atm.bottom_radius;
    std::vector<double> err(kN, 0.0);
    std::vector<char> ok(kN, 1);
    ParallelFor(kN, 1, [&](int64_t i) {
        const double x = static_cast<double>(i) / (kN - 1);
        const double r = atm.bottom_radius + delta * x * x * x * x * (1.0 - 1e-9);
        for (int j = 0; j < kN; ++j) {
            const double y = (j + 0.5) / (kN / 2) - 1.0;
            const double mu = y < 0.0 ? -y * y : y * y;
            if (RayIntersectsGround(r, mu, atm.bottom_radius)) continue;
            const Vec3d p(0.0, 0.0, r);
            const Vec3d dir(std::sqrt(std::max(1.0 - mu * mu, 0.0)), 0.0, mu);
            const Vec3d exact = Exp(-AdaptiveOpticalDepth(
                atm, p, dir, DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius)));
            const Vec3d t = table.Lookup(r, mu);
            for (int c = 0; c < 3; ++c) {
                const double d = std::abs(t[c] - exact[c]);
                err[i] = std::max(err[i], d);
                if (d > 1e-3 || (exact[c] > 0.01 && d > 1e-2 * exact[c])) ok[i] = 0;
            }
        }
    });
    if (worst) *worst = *std::max_element(err.begin(), err.end());
    return std::all_of(ok.begin(), ok.end(), [](char v) { return v != 0; });
}

std::shared_ptr<const Table> SharedSunColumnTable(const AtmosphereParameters& atm) {
    // The geometry: radii and the three density profiles (5 numbers per layer).
    std::vector<double> key = {atm.bottom_radius, atm.top_radius};
    for (const DensityProfile* p :
         {&atm.rayleigh_density, &atm.mie_density, &atm.absorption_density}) {
        for (const DensityProfileLayer& l : p->layers) {
            key.insert(key.end(),
                       {l.width, l.exp_term, l.exp_scale, l.linear_term, l.constant_term});
        }
    }
    // The last few geometries (1.5 MB each; the batches of a run share one).
    constexpr size_t kKeep = 8;
    static std::mutex mutex;
    static std::vector<std::pair<std::vector<double>, std::shared_ptr<const Table>>> tables;
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [k, table] : tables) {
        if (k == key) return table;
    }
    if (tables.size() >= kKeep) tables.erase(tables.begin());
    tables.emplace_back(key, std::make_shared<const Table>(BuildSunColumnTable(
                                 atm, kSunTableMuSize, kSunTableRSize, kSunTableIntervals)));
    return tables.back().second;
}

ModelInfo ReferenceModel::StaticInfo() {
    ModelInfo info;
    info.name = "reference";
    info.title = "Reference path tracer (spectral tracking)";
    info.citation =
        "Leenman's 2025 thesis sections 3.2, 4, 11.2.2; Kutz et al. 2017 (spectral tracking); "
        "Novak et al. "
        "2014 (ratio tracking)";
    info.summary = "unbiased Monte Carlo: all scattering orders, planet shadow, Lambertian ground";
    info.capabilities.multiple_scattering = true;
    info.capabilities.stochastic = true;
    info.capabilities.spectral_paths = true;  // with spectral=hero (the constructor)
    info.options = OptionRows().Specs();
    info.thesis_name = "Path tracer";
    info.thesis_lines = 147;
    return info;
}

const OptionTable<ReferenceOptions>& ReferenceModel::OptionRows() {
    using O = ReferenceOptions;
    static const auto table =
        OptionTable<O>()
            .Integer("sun-disc-light", &O::sun_disc_light, 0, 1, "",
                     "1: light from the sun's disc (angular radius from the atmosphere), sampled "
                     "per next-event estimate; 0: a directional sun like the other models")
            .Choice("estimator", &O::estimator,
                    {{"hybrid", ReferenceEstimator::kHybrid},
                     {"tracking", ReferenceEstimator::kTracking},
                     {"spectral", ReferenceEstimator::kTracking},
                     {"thesis", ReferenceEstimator::kThesis}},
                    "hybrid: order 1 by converged quadrature along the view ray, orders >= 2 by "
                    "paths whose first vertex is drawn from the same table, the sun's "
                    "transmittance from a converged table, looser continuation majorants; "
                    "tracking (alias spectral): spectral tracking, forced first collision, "
                    "ratio-tracked sun (the default before 0.6); thesis: the thesis's estimator "
                    "(one random channel per path, delta tracking, uniform directions), kept as "
                    "a baseline")
            .Integer("max-order", &O::max_order, 0, 1e6, "",
                     "highest scattering order (volume or ground vertices); 0: unlimited")
            .Integer("shells", &O::shells, 0, kMaxReferenceShells, "",
                     "altitude shells of the majorant (1: one global majorant; 0: 8 for hybrid, "
                     "48 for tracking and thesis)")
            .Real("majorant-scale", &O::majorant_scale, 1.0, 64.0, "",
                  "hybrid: factor on the majorants of continuation segments (more, cheaper "
                  "next-event estimates per path)")
            .Integer("nee-comb", &O::nee_comb, 0, kMaxNeeComb, "",
                     "hybrid: stratified uniform next-event points per continuation segment "
                     "that starts with the sun below its horizon (twilight), MIS-weighted with "
                     "the collisions' estimates (0: none)")
            .Real("sun-lobe", &O::sun_lobe, 0.0, 0.95, "",
                  "hybrid: probability of drawing the first continuation direction from a "
                  "Henyey-Greenstein lobe around the sun at a first vertex with the sun below "
                  "its horizon (twilight; MIS with the phase function; 0: none)")
            .Real("sun-lobe-g", &O::sun_lobe_g, 0.0, 0.99, "",
                  "hybrid: the sun lobe's Henyey-Greenstein g")
            .Choice("spectral", &O::hero, {{"hero", true}, {"batches", false}},
                    "spectral runs (--wavelengths, more than three): hero: every path carries "
                    "all the wavelengths (hero-wavelength sampling, spectral MIS; hybrid "
                    "estimator, radiance without the sun's disc or a noise target, CPU); "
                    "batches: a set of paths per batch of three wavelengths");
    return table;
}

ReferenceModel::ReferenceModel(const ReferenceOptions& options) : info_(StaticInfo()) {
    const bool hybrid = options.estimator == ReferenceEstimator::kHybrid;
    if (hybrid && options.sun_disc_light != 0) {
        Fail(
            "model reference: sun-disc-light=1 needs estimator=tracking (the hybrid "
            "estimator's order 1 is for a directional sun)");
    }
    shell_count_ = options.shells > 0 ? options.shells : (hybrid ? 8 : 48);
    evaluator_.max_order = options.max_order;
    evaluator_.estimator = options.estimator;
    evaluator_.spectral = options.estimator != ReferenceEstimator::kThesis;
    evaluator_.continuation_majorant_scale = options.majorant_scale;
    evaluator_.nee_comb = options.nee_comb;
    evaluator_.sun_lobe = options.sun_lobe;
    evaluator_.sun_lobe_g = options.sun_lobe_g;
    sun_disc_light_ = options.sun_disc_light != 0;
    info_.capabilities.spectral_paths = options.hero && hybrid;
    Prepare(EarthAtmosphere());
}

void ReferenceModel::Prepare(const AtmosphereParameters& atmosphere) {
    evaluator_.atm = atmosphere;
    evaluator_.sun_cone_cos = sun_disc_light_ ? std::cos(atmosphere.sun_angular_radius) : 1.0;
    evaluator_.shells = BuildMajorantShells(atmosphere, shell_count_, hero_groups_);
    std::lock_guard<std::mutex> lock(sun_table_mutex_);
    resident_.Reset();
    sun_table_ready_ = false;
    // Until built: a valid table for a device copy.
    sun_table_ = std::make_shared<const Table>(2, 2, 1, 3);
    evaluator_.sun_table.Set(sun_table_->view(), atmosphere);
    // The model's evaluator never names an order-1 table (only a pass's copy
    // does, holding the table alive: Order1Table), so no copy of it can name
    // a freed one.
    order1_table_.reset();
    order1_key_.clear();
    evaluator_.order1_table = TableView();
    evaluator_.order1_cached = false;
}

const ReferenceEvaluator& ReferenceModel::evaluator() const {
    std::lock_guard<std::mutex> lock(sun_table_mutex_);
    if (!sun_table_ready_ && evaluator_.estimator == ReferenceEstimator::kHybrid) {
        sun_table_ = SharedSunColumnTable(evaluator_.atm);
        evaluator_.sun_table.Set(sun_table_->view(), evaluator_.atm);
        evaluator_.sun_table.direct = !SunTableResolves(evaluator_.sun_table, evaluator_.atm);
    }
    sun_table_ready_ = true;
    return evaluator_;
}

std::string ReferenceModel::PassKey() const {
    nlohmann::json key;
    // Bumped with any change that could move the expected value: a checkpoint
    // or a shard of an older estimator is another render (issue 36).
    key["estimator_version"] = kReferenceEstimatorVersion;
    key["max_order"] = evaluator_.max_order;
    key["estimator"] = evaluator_.estimator == ReferenceEstimator::kHybrid     ? "hybrid"
                       : evaluator_.estimator == ReferenceEstimator::kTracking ? "spectral"
                                                                               : "thesis";
    if (evaluator_.estimator == ReferenceEstimator::kHybrid) {
        key["majorant_scale"] = evaluator_.continuation_majorant_scale;
        key["nee_comb"] = evaluator_.nee_comb;
        key["sun_lobe"] = {evaluator_.sun_lobe, evaluator_.sun_lobe_g};
        key["sun_table"] = {kSunTableMuSize, kSunTableRSize, kSunTableIntervals};
    }
    key["sun_cone_cos"] = evaluator_.sun_cone_cos;
    key["shells"] = evaluator_.shells.count;
    key["atmosphere"] = nlohmann::json::parse(AtmosphereToJson(evaluator_.atm));
    return key.dump();
}

void ReferenceModel::RenderPass(const RenderRequest& request, const MonteCarloPass& pass,
                                Image* out, Progress* progress) const {
    PixelSetup setup = MakePixelSetup(request, evaluator_.atm);
    // The pass's band of rows (checkpoints may fall between bands).
    setup.first_row = pass.row_begin;
    out->Resize(request.width, pass.rows > 0 ? pass.rows : request.height - pass.row_begin);
    ReferenceEvaluator e = evaluator();
    e.seed = pass.seed;
    if (request.quantity == Quantity::kTransmittance) {
        // Deterministic: no paths needed (T does not depend on them).
        e.sample_count = 0;
    } else {
        e.sample_begin = pass.first_sample;
        e.sample_count = pass.samples;
        e.need_transmittance = request.sun_disc;  // the only use of T in a radiance pass
    }
    // The sun table (and order 1) stay on the device from pass to pass.
    ResidentScope scope(&resident_);
    std::shared_ptr<const Table> order1;  // alive for the pass, whatever later requests do
    if (request.quantity != Quantity::kTransmittance &&
        e.estimator == ReferenceEstimator::kHybrid) {
        // Its bar shows where the pass's does (RenderImageInterruptible).
        const LibraryProgressScope bar(progress != nullptr && progress->active());
        order1 = Order1Table(setup, e);
        e.order1_table = order1->view();
        e.order1_cached = true;
    }
    scope.Keep(e);
    RenderImage(e, setup, out->View(), progress);
}

std::shared_ptr<const Table> ReferenceModel::Order1Table(const PixelSetup& setup,
                                                         const ReferenceEvaluator& e) const {
    // Deterministic work, the same in every pass: once per request.
    const Camera& c = setup.camera;
    std::vector<double> key = {c.position.x,
                               c.position.y,
                               c.position.z,
                               c.forward.x,
                               c.forward.y,
                               c.forward.z,
                               c.right.x,
                               c.right.y,
                               c.right.z,
                               c.up.x,
                               c.up.y,
                               c.up.z,
                               c.tan_half_fov_y,
                               static_cast<double>(c.projection),
                               c.half_fov,
                               setup.sun_direction.x,
                               setup.sun_direction.y,
                               setup.sun_direction.z,
                               static_cast<double>(setup.width),
                               static_cast<double>(setup.height)};
    std::lock_guard<std::mutex> lock(sun_table_mutex_);
    if (!order1_table_ || key != order1_key_) {
        ReferenceEvaluator first = e;
        first.max_order = 1;
        first.sample_begin = 0;
        first.sample_count = 1;
        first.order1_cached = false;
        PixelSetup unit = setup;
        unit.irradiance = Rgb(1.0f);  // sky + ground per unit irradiance
        unit.sun_disc = false;
        unit.first_row = 0;  // the whole image, whatever band the pass renders
        Image image;
        image.Resize(setup.width, setup.height);
        // In bands that act on a stop signal and show progress (issue 39 item 1).
        RenderImageInterruptible(first, unit, image.View(), LibraryProgressEnabled(),
                                 "reference: order 1");
        auto table = std::make_shared<Table>(setup.width, setup.height, 1, 3);
        for (int y = 0; y < setup.height; ++y) {
            for (int x = 0; x < setup.width; ++x) {
                const Rgb v = image.Get(x, y);
                float* texel = table->Texel(x, y);
                for (int ch = 0; ch < 3; ++ch) texel[ch] = v[ch];
            }
        }
        // A pass still rendering with the previous table keeps it alive.
        order1_table_ = std::move(table);
        order1_key_ = key;
    }
    return order1_table_;
}

std::vector<SampleAnswer> ReferenceModel::SamplePass(const std::vector<SampleQuery>& queries,
                                                     const MonteCarloPass& pass) const {
    ReferenceEvaluator e = evaluator();
    e.seed = pass.seed;
    e.sample_begin = pass.first_sample;
    e.sample_count = pass.samples;
    ResidentScope scope(&resident_);
    scope.Keep(e);
    return SampleAll(e, e.atm.bottom_radius, queries);
}

void ReferenceModel::SetSpectralPaths(const SpectralAtmosphere& atmosphere,
                                      const std::vector<double>& nm) {
    if (!info_.capabilities.spectral_paths) {
        Fail(
            "model reference: paths that carry many wavelengths need estimator=hybrid and "
            "spectral=hero");
    }
    hero_groups_.clear();
    Vec3d scale;
    for (double l : nm) {
        scale =
            Max(scale, Vec3d(atmosphere.rayleigh_scattering.At(l), atmosphere.mie_extinction.At(l),
                             atmosphere.absorption_extinction.At(l)));
    }
    for (size_t i = 0; i < nm.size(); ++i) {
        if (i % kHeroMaxChannels == 0) {
            hero_groups_.emplace_back();
            hero_groups_.back().column_scale = scale;
        }
        HeroSpectrum& s = hero_groups_.back();
        const int c = s.count++;
        const double l = nm[i];
        s.rayleigh[c] = atmosphere.rayleigh_scattering.At(l);
        s.mie_scattering[c] = atmosphere.mie_scattering.At(l);
        s.mie_extinction[c] = atmosphere.mie_extinction.At(l);
        s.absorption[c] = atmosphere.absorption_extinction.At(l);
        s.albedo[c] = atmosphere.ground_albedo.At(l);
    }
}

namespace {

// The hero evaluator of `e` for one group of channels.
ReferenceHero HeroOf(const ReferenceEvaluator& e, const HeroSpectrum& spectrum) {
    ReferenceHero hero;
    static_cast<ReferenceHybrid&>(hero) = e;
    hero.spec = spectrum;
    hero.order1_cached = false;
    hero.order1_table = TableView();
    return hero;
}

}  // namespace

void ReferenceModel::RenderSpectralPaths(const RenderRequest& request,
                                         std::vector<float>* values) const {
    if (hero_groups_.empty()) Fail("model reference: RenderSpectralPaths before SetSpectralPaths");
    if (request.quantity != Quantity::kRadiance || request.sun_disc) {
        Fail(
            "model reference: paths that carry many wavelengths render radiance without the "
            "sun's disc");
    }
    const PixelSetup setup = MakePixelSetup(request, evaluator_.atm);
    size_t n = 0;
    for (const HeroSpectrum& g : hero_groups_) n += static_cast<size_t>(g.count);
    const size_t width = static_cast<size_t>(request.width);
    values->assign(width * static_cast<size_t>(request.height) * n, 0.0f);
    const int64_t spp = std::max<int64_t>(request.monte_carlo.spp, 1);
    const double inv = 1.0 / static_cast<double>(spp);
    size_t offset = 0;
    for (const HeroSpectrum& group : hero_groups_) {
        ReferenceHero hero = HeroOf(evaluator(), group);
        hero.seed = request.monte_carlo.seed;
        hero.sample_begin = 0;
        hero.sample_count = spp;
        hero.need_transmittance = false;
        ParallelFor(request.height, 1, [&](int64_t y) {
            double sky[kHeroMaxChannels], ground[kHeroMaxChannels];
            for (int x = 0; x < request.width; ++x) {
                const Vec3d dir =
                    setup.camera.RayDirection(x, static_cast<int>(y), setup.width, setup.height);
                if (dir.x == 0.0 && dir.y == 0.0 && dir.z == 0.0) continue;
                const uint64_t key = static_cast<uint64_t>(y) * width + static_cast<uint64_t>(x);
                hero.EvaluateHero(setup.camera.position, dir, setup.sun_direction, true, key, sky,
                                  ground);
                float* out = values->data() + (static_cast<size_t>(y) * width + x) * n + offset;
                for (int c = 0; c < group.count; ++c) {
                    out[c] = static_cast<float>(sky[c] * inv) + static_cast<float>(ground[c] * inv);
                }
            }
        });
        offset += static_cast<size_t>(group.count);
    }
    GuardOutput(values->data(), values->size());
}

std::vector<float> ReferenceModel::SampleSpectralPaths(const std::vector<SampleQuery>& queries,
                                                       const MonteCarloSettings& mc) const {
    if (hero_groups_.empty()) Fail("model reference: SampleSpectralPaths before SetSpectralPaths");
    size_t n = 0;
    for (const HeroSpectrum& g : hero_groups_) n += static_cast<size_t>(g.count);
    std::vector<float> values(queries.size() * n, 0.0f);
    const int64_t spp = std::max<int64_t>(mc.spp, 1);
    const double inv = 1.0 / static_cast<double>(spp);
    size_t offset = 0;
    for (const HeroSpectrum& group : hero_groups_) {
        ReferenceHero hero = HeroOf(evaluator(), group);
        hero.seed = mc.seed;
        hero.sample_begin = 0;
        hero.sample_count = spp;
        hero.need_transmittance = false;
        ParallelFor(static_cast<int64_t>(queries.size()), 1, [&](int64_t i) {
            const SampleQuery& q = queries[static_cast<size_t>(i)];
            Vec3d dir, sun;
            SampleDirections(q, &dir, &sun);
            const Vec3d camera(0.0, 0.0, hero.atm.bottom_radius + q.altitude_m);
            double sky[kHeroMaxChannels], ground[kHeroMaxChannels];
            hero.EvaluateHero(camera, dir, sun, q.ground != 0, SampleQueryKey(q), sky, ground);
            float* out = values.data() + static_cast<size_t>(i) * n + offset;
            for (int c = 0; c < group.count; ++c) {
                // As SampleOne: the float sky (+ the float ground).
                out[c] = static_cast<float>(sky[c] * inv);
                if (q.ground != 0) out[c] += static_cast<float>(ground[c] * inv);
            }
        });
        offset += static_cast<size_t>(group.count);
    }
    GuardOutput(values.data(), values.size());
    return values;
}

}  // namespace atmos
