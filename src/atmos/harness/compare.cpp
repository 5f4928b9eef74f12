// atmos: the comparison harness (see compare.h).
#include "harness/compare.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "atmos/error.h"
#include "base/fnv1a.h"
#include "base/parallel.h"
#include "harness/compare_regions.h"
#include "harness/ranking.h"
#include "harness/regimes.h"
#include "harness/render_cache.h"
#include "harness/report.h"
#include "harness/shipped_references.h"
#include "harness/spectral_run.h"
#include "io/output_path.h"
#include "metrics/rmse.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

double SecondsSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string CacheViewName(const View& view);

// A model's images, rendered on demand: Prepare() runs once, only if some
// image is not in the cache.
class LazyRenderer {
  public:
    LazyRenderer(std::string name, std::map<std::string, std::string> options,
                 const CompareConfig& config, const RenderCache& cache,
                 const MonteCarloSettings& monte_carlo = MonteCarloSettings())
        : name_(std::move(name)),
          options_(std::move(options)),
          config_(config),
          cache_(cache),
          monte_carlo_(monte_carlo) {
        wavelengths_ = config.wavelengths;
        key_.model = name_;
        key_.options = ResolvedModelOptions(name_, options_);
        key_.monte_carlo = GetModelInfo(name_).capabilities.stochastic;
        key_.mc = monte_carlo_;
        key_.atmosphere_json = AtmosphereToJson(config.atmosphere);
        key_.width = config.width;
        key_.height = config.height;
        key_.quantity = config.quantity;
    }

    // `variance` (optional, Monte Carlo models): the per-pixel variance of
    // the estimate, empty when a cached image has none.
    Image Render(const View& view, double* seconds, bool* cached,
                 MonteCarloReport* report = nullptr, Image* variance = nullptr) {
        RenderKey key = key_;
        key.view = CacheViewName(view);
        Image image;
        MonteCarloReport local;
        if (!report) report = &local;
        if (!wavelengths_.empty()) return RenderSpectralColour(view, seconds, cached, report);
        if (cache_.Load(key, &image, seconds, report, variance)) {
            *cached = true;
            return image;
        }
        if (!model_) {
            model_ = CreateModel(name_, options_);
            const auto start = std::chrono::steady_clock::now();
            model_->Prepare(config_.atmosphere);
            prepare_seconds_ = SecondsSince(start);
            prepared_ = true;
            table_bytes_ = model_->TableBytes();
            cache_.StorePrepare(key_, prepare_seconds_, table_bytes_);
        }
        RenderRequest request;
        request.view = view;
        request.width = config_.width;
        request.height = config_.height;
        request.quantity = config_.quantity;
        request.show_progress = config_.show_progress;
        request.monte_carlo = monte_carlo_;
        request.report = report;
        if (key.monte_carlo) request.variance = variance;
        const auto start = std::chrono::steady_clock::now();
        model_->Render(request, &image);
        *seconds = SecondsSince(start);
        *cached = false;
        cache_.Store(key, image, *seconds, key.monte_carlo ? report : nullptr,
                     key.monte_carlo ? variance : nullptr);
        return image;
    }

    // The views of the run (a spectral run renders them all on the first call).
    void SetViews(const std::vector<View>& views) { views_ = views; }
    // Render at these wavelengths (the constructor takes config.wavelengths).
    void SetWavelengths(const std::vector<double>& nm) { wavelengths_ = nm; }
    double prepare_seconds() const { return prepare_seconds_; }
    bool prepared() const { return prepared_; }
    int64_t table_bytes() const { return table_bytes_; }
    // Not prepared in this run: the cache's record of the last Prepare().
    void LoadPrepareRecord() {
        if (prepared_) return;
        double seconds = 0.0;
        int64_t bytes = -1;
        if (cache_.LoadPrepare(key_, &seconds, &bytes)) {
            prepare_seconds_ = seconds;
            table_bytes_ = bytes;
        }
    }

  private:
    // --wavelengths: the views at every wavelength, as linear sRGB. The first
    // call renders every view of the run (SetViews; in groups of at most 1 GiB of
    // spectral images), batch by batch, so that each batch's model is prepared
    // once for all views of the group (counted in prepare_seconds);
    // the colour images are kept for the later calls. A Monte Carlo report gives
    // the paths per pixel over all batches and the largest batch noise.
    Image RenderSpectralColour(const View& view, double* seconds, bool* cached,
                               MonteCarloReport* report) {
        if (spectral_views_.find(view.name) == spectral_views_.end()) {
            RenderRequest sized;
            sized.width = config_.width;
            sized.height = config_.height;
            const std::vector<RenderRequest> all(views_.size(), sized);
            // The group of views (at most 1 GiB of spectral images) holding `view`.
            std::vector<View> group_views;
            for (const std::vector<size_t>& group :
                 SpectralRequestGroups(all, wavelengths_.size())) {
                for (size_t v : group) {
                    if (views_[v].name == view.name) {
                        for (size_t w : group) group_views.push_back(views_[w]);
                    }
                }
            }
            if (group_views.empty()) Fail("compare: view '", view.name, "' not in the run");
            std::vector<RenderRequest> requests;
            for (const View& v : group_views) {
                RenderRequest request;
                request.view = v;
                request.width = config_.width;
                request.height = config_.height;
                request.quantity = config_.quantity;
                request.show_progress = false;
                request.monte_carlo = monte_carlo_;
                requests.push_back(request);
            }
            double prepare = 0.0;
            std::vector<double> render_seconds;
            std::vector<MonteCarloReport> reports;
            const std::vector<SpectralImage> spectral = RenderSpectralRequests(
                ModelSpec{name_, name_, options_}, config_.spectral_atmosphere, wavelengths_,
                requests,
                [&](const AtmosphereParameters& a, Model* m) {
                    const auto p0 = std::chrono::steady_clock::now();
                    m->Prepare(a);
                    prepare += SecondsSince(p0);
                },
                &render_seconds, &reports, config_.batching);
            prepare_seconds_ += prepare;
            prepared_ = true;
            for (size_t v = 0; v < group_views.size(); ++v) {
                SpectralView& out = spectral_views_[group_views[v].name];
                out.image = SpectralToColour(spectral[v], ColourOutput::kSrgb, config_.white);
                out.seconds = render_seconds[v];
                out.report = reports[v];
            }
        }
        const auto it = spectral_views_.find(view.name);
        if (it == spectral_views_.end()) Fail("compare: view '", view.name, "' not in the run");
        *seconds = it->second.seconds;
        *cached = false;
        *report = it->second.report;
        return it->second.image;
    }

    struct SpectralView {
        Image image;
        double seconds = 0.0;
        MonteCarloReport report;
    };
    std::vector<View> views_;
    std::vector<double> wavelengths_;
    std::map<std::string, SpectralView> spectral_views_;
    std::string name_;
    std::map<std::string, std::string> options_;
    const CompareConfig& config_;
    const RenderCache& cache_;
    MonteCarloSettings monte_carlo_;
    RenderKey key_;
    std::unique_ptr<Model> model_;
    double prepare_seconds_ = 0.0;
    bool prepared_ = false;
    int64_t table_bytes_ = -1;
};

// The render cache's name of a view: a named view's name; a custom view's
// name and a hash of its geometry (the same name may mean another camera in
// another views file).
std::string CacheViewName(const View& view) {
    const std::vector<std::string> names = StandardViewNames();
    if (std::find(names.begin(), names.end(), view.name) != names.end()) return view.name;
    std::string text = ViewFingerprintText(view);
    text += "projection " + std::to_string(static_cast<int>(view.camera.projection)) + "\n";
    char buf[96];
    std::snprintf(buf, sizeof buf, "half_fov %.17g\nlimb %.17g\n", view.camera.half_fov,
                  view.sun_limb_darkening);
    text += buf;
    return view.name + "-" + Fnv1aHex(Fnv1a64(text));
}

std::string FileStem(const std::string& name) {
    std::string s;
    for (char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                        (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
        s += ok ? c : '_';
    }
    return s;
}

CompareLuminance ScaledLuminance(const RegionLuminance& y, double scale) {
    CompareLuminance l;
    l.all = y.all * scale;
    l.sky = y.sky * scale;
    l.ground = y.ground * scale;
    return l;
}

void WriteImages(const Image& image, const fs::path& dir, const std::string& stem, float exposure,
                 bool npy) {
    WriteImage(image, (dir / (stem + ".png")).string(), exposure);
    WriteImage(image, (dir / (stem + ".exr")).string());
    if (npy) WriteImage(image, (dir / (stem + ".npy")).string());
}

}  // namespace

std::vector<std::string> DefaultCompareViews(Quantity quantity) {
    if (quantity == Quantity::kTransmittance) {
        return {"ground-noon", "plane-noon", "orbit-noon", "space", "planet-shadow-orbit"};
    }
    return StandardViewNames();
}

std::string CompareRowLabel(const std::string& view, Quantity quantity) {
    if (quantity == Quantity::kTransmittance) {
        for (const char* place : {"ground", "plane", "orbit"}) {
            const std::string p = place;
            if (view == p + "-noon" || view == p + "-sunrise" || view == p + "-dawn") return p;
        }
    }
    return view;
}

std::string ValidityNote(const ModelCapabilities& caps, const View& view,
                         const AtmosphereParameters& atmosphere) {
    std::string note;
    const double r = Length(view.camera.position);
    const double altitude = r - atmosphere.bottom_radius;
    if (!caps.space_views && altitude > 1.0) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "declared valid on the ground only (camera at %.0f km)",
                      altitude / 1000.0);
        note = buf;
    }
    const Vec3d up = view.camera.position / r;
    if (!caps.sun_below_horizon && Dot(view.sun_direction, up) < 0.0) {
        if (!note.empty()) note += "; ";
        note += "declared valid with the sun above the horizon only";
    }
    return note;
}

int BestIndex(const std::vector<double>& row) {
    int best = -1;
    for (size_t i = 0; i < row.size(); ++i) {
        if (!std::isfinite(row[i])) continue;
        if (best < 0 || row[i] < row[static_cast<size_t>(best)]) best = static_cast<int>(i);
    }
    return best;
}

void WriteMetricCsv(const std::string& path, const std::string& corner,
                    const std::vector<std::string>& row_labels,
                    const std::vector<std::string>& columns,
                    const std::vector<std::vector<double>>& values,
                    const std::vector<double>& row_noise) {
    TextOutput f(path);
    f << corner;
    for (const std::string& c : columns) f << "," << c;
    f << ",best\n";
    for (size_t r = 0; r < row_labels.size(); ++r) {
        f << row_labels[r];
        for (double v : values[r]) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.8g", v);
            f << "," << (std::isfinite(v) ? buf : "");
        }
        const double noise = r < row_noise.size() ? row_noise[r] : -1.0;
        std::string best;
        for (int m : BestOfRow(values[r], noise)) {
            best += (best.empty() ? "" : " ") + columns[static_cast<size_t>(m)];
        }
        f << "," << best << "\n";
    }
    f.Commit();
}

CompareResult RunCompare(const CompareConfig& config) {
    const auto start = std::chrono::steady_clock::now();
    CompareResult result;
    result.threads = ParallelThreadCount();
    const bool transmittance = config.quantity == Quantity::kTransmittance;

    // Models: those given (with their options), or every registered one
    // producing the quantity.
    std::vector<ModelSpec> specs;
    if (config.models.empty()) {
        for (const ModelInfo& info : ListModels()) {
            if (info.capabilities.stochastic) continue;  // Monte Carlo: a reference
            if (!config.wavelengths.empty() && !HasSpectralForm(info)) continue;
            if (transmittance ? !info.capabilities.transmittance : !info.capabilities.radiance) {
                continue;
            }
            specs.push_back(ParseModelSpec(info.name));
        }
    } else {
        for (const std::string& m : config.models) {
            const ModelSpec spec = ParseModelSpec(m);
            const ModelInfo& info = GetModelInfo(spec.name);
            if (transmittance ? !info.capabilities.transmittance : !info.capabilities.radiance) {
                Fail("model '", m, "' does not produce ", QuantityName(config.quantity));
            }
            for (const ModelSpec& other : specs) {
                if (other.text == spec.text) Fail("compare: model '", m, "' given twice");
            }
            specs.push_back(spec);
        }
    }
    if (specs.empty()) Fail("compare: no model to compare");
    for (const ModelSpec& spec : specs) {
        result.models.push_back(spec.text);
        result.model_names.push_back(spec.name);
        std::string title = GetModelInfo(spec.name).title;
        for (const auto& [option, value] : spec.options) title += ", " + option + "=" + value;
        result.model_titles.push_back(title);
    }
    const std::vector<std::string> view_names =
        config.views.empty() ? DefaultCompareViews(config.quantity) : config.views;
    std::vector<View> views;
    for (const std::string& v : view_names) {
        const auto custom = std::find_if(config.custom_views.begin(), config.custom_views.end(),
                                         [&](const View& c) { return c.name == v; });
        views.push_back(custom != config.custom_views.end() ? *custom
                                                            : GetView(v, config.atmosphere));
    }

    const RenderCache cache(config.cache_dir);
    // A Monte Carlo reference: two independent halves, averaged (the same
    // number of paths), whose difference measures its noise.
    const ModelInfo& reference_info = GetModelInfo(config.reference_model);
    const MonteCarloSettings& mc = config.reference_monte_carlo;
    // A noise target: one render whose even and odd passes are the halves
    // (render/progressive.h), until their FLIP reaches the target.
    const bool noise_target =
        !transmittance && reference_info.capabilities.stochastic && mc.noise_target > 0.0;
    const bool split_reference =
        !noise_target && !transmittance && reference_info.capabilities.stochastic && mc.spp >= 2;
    MonteCarloSettings half_a = mc, half_b = mc;
    int64_t spp_a = 0, spp_b = 0;
    if (split_reference) {
        spp_a = mc.spp / 2;
        spp_b = mc.spp - spp_a;
        half_a.spp = spp_a;
        half_b.spp = spp_b;
        half_a.seed = 2 * mc.seed + 1;
        half_b.seed = 2 * mc.seed + 2;
    }
    MonteCarloSettings whole = mc;
    if (!noise_target) whole.noise_target = 0.0;
    LazyRenderer reference(config.reference_model, config.reference_options, config, cache,
                           split_reference ? half_a : whole);
    LazyRenderer reference_b(config.reference_model, config.reference_options, config, cache,
                             half_b);
    std::vector<std::unique_ptr<LazyRenderer>> renderers;
    for (const ModelSpec& spec : specs) {
        renderers.push_back(std::make_unique<LazyRenderer>(spec.name, spec.options, config, cache));
        renderers.back()->SetViews(views);
    }
    reference.SetViews(views);
    reference_b.SetViews(views);
    // What RGB costs: the reference spectral, and the RGB reference beside it.
    const bool spectral_reference = !config.reference_wavelengths.empty();
    if (spectral_reference) {
        if (!config.wavelengths.empty()) {
            Fail("compare: --reference-wavelengths compares RGB models (no --wavelengths)");
        }
        if (transmittance) Fail("compare: --reference-wavelengths compares radiance");
        reference.SetWavelengths(config.reference_wavelengths);
        reference_b.SetWavelengths(config.reference_wavelengths);
    }
    LazyRenderer rgb_reference(config.reference_model, config.reference_options, config, cache,
                               whole);
    rgb_reference.SetViews(views);
    // Shipped references (RGB radiance, a Monte Carlo reference): read once; a
    // damaged set is a warning and every view renders.
    std::unique_ptr<ShippedReferences> shipped;
    ReferenceFingerprint run_fingerprint;
    if (!config.shipped_references.empty() && !transmittance && config.wavelengths.empty() &&
        !spectral_reference && reference_info.capabilities.stochastic) {
        try {
            run_fingerprint = MakeReferenceFingerprint(
                config.reference_model, config.reference_options, config.atmosphere_name,
                config.atmosphere, config.width, config.height, views);
            shipped = std::make_unique<ShippedReferences>(
                ReadShippedReferences(config.shipped_references));
        } catch (const Error& e) {
            std::fprintf(stderr, "atmos: warning: shipped references not used: %s\n", e.what());
        }
    }

    for (const View& view : views) {
        CompareRow row;
        row.view = view.name;
        row.label = CompareRowLabel(view.name, config.quantity);
        row.description = view.description;
        row.exposure = transmittance ? 1.0f : view.exposure;
        row.place = PlaceRegime(view, config.atmosphere);
        row.light = LightRegime(view, config.atmosphere);
        const std::vector<uint8_t> mask =
            RegionMask(view, config.width, config.height, config.atmosphere.bottom_radius);
        const RegionCounts counts = CountRegions(mask);
        row.sky_pixels = counts.sky;
        row.ground_pixels = counts.ground;
        MonteCarloReport ref_report;
        Image ref_variance;  // per-pixel variance of the reference's estimate (may stay empty)
        Image ref;
        if (shipped) {
            // The shipped image when it matches the run and is at least as good as
            // the run's render would be (its noise at or below the target, or at
            // least the run's paths per pixel).
            const std::string why = LoadMatchingShippedView(*shipped, run_fingerprint, view.name,
                                                            noise_target ? mc.noise_target : 0.0,
                                                            mc.spp, &ref, &ref_variance);
            if (why.empty()) {
                const ShippedView& v = *shipped->Find(view.name);
                row.reference_source = "shipped";
                row.reference_spp = v.paths_per_pixel;
                row.reference_noise = v.noise;
                row.reference_provenance =
                    (fs::path(shipped->directory) / "provenance.json").string() +
                    (v.commit.empty() ? "" : " (commit " + v.commit.substr(0, 12) + ")");
            } else {
                std::fprintf(stderr, "%s: shipped reference not used: %s\n", view.name.c_str(),
                             why.c_str());
            }
        }
        const bool from_shipped = row.reference_source == "shipped";
        if (!from_shipped) {
            ref = reference.Render(view, &row.reference_seconds, &row.reference_cached, &ref_report,
                                   &ref_variance);
            row.reference_spp = ref_report.samples;
            if (noise_target) {
                row.reference_noise = ref_report.noise;
                // The halves' FLIP map at the render's last measurement (its
                // mean is reference_noise), over each region as for a split
                // reference; a spectral reference has none (whole-image noise).
                if (!ref_report.noise_map.empty()) {
                    const RegionValues noise = RegionMean(ref_report.noise_map, mask);
                    row.reference_noise_sky = std::isfinite(noise.sky) ? noise.sky : -1.0;
                    row.reference_noise_ground = std::isfinite(noise.ground) ? noise.ground : -1.0;
                }
            }
        }
        if (split_reference && !from_shipped) {
            double seconds_b = 0.0;
            bool cached_b = false;
            Image variance_b;
            const Image b = reference_b.Render(view, &seconds_b, &cached_b, nullptr, &variance_b);
            const FlipResult halves = HdrFlip(ref, b, config.flip);
            row.reference_noise = halves.mean;
            const RegionValues noise = RegionMean(halves.map, mask);
            row.reference_noise_sky = std::isfinite(noise.sky) ? noise.sky : -1.0;
            row.reference_noise_ground = std::isfinite(noise.ground) ? noise.ground : -1.0;
            const float wa = static_cast<float>(spp_a) / static_cast<float>(spp_a + spp_b);
            // The variance of the weighted mean: from the halves' own estimates,
            // else from their difference (E[(a - b)^2] = var_a + var_b).
            if (ref_variance.size() == ref.size() && variance_b.size() == b.size()) {
                for (size_t i = 0; i < ref.size(); ++i) {
                    ref_variance.data()[i] = wa * wa * ref_variance.data()[i] +
                                             (1.0f - wa) * (1.0f - wa) * variance_b.data()[i];
                }
            } else {
                ref_variance.Resize(ref.width(), ref.height());
                for (size_t i = 0; i < ref.size(); ++i) {
                    const float d = ref.data()[i] - b.data()[i];
                    ref_variance.data()[i] = d * d * 0.25f;
                }
            }
            for (size_t i = 0; i < ref.size(); ++i) {
                ref.data()[i] = wa * ref.data()[i] + (1.0f - wa) * b.data()[i];
            }
            row.reference_seconds += seconds_b;
            row.reference_spp = spp_a + spp_b;
            row.reference_cached = row.reference_cached && cached_b;
        }
        if (row.reference_cached) row.reference_source = "cached";
        if (ref_variance.size() == ref.size() && ref.size() > 0) {
            double sum = 0.0;
            for (size_t i = 0; i < ref_variance.size(); ++i)
                sum += static_cast<double>(ref_variance.data()[i]);
            row.reference_rmse_noise = 2.0 * std::sqrt(sum / static_cast<double>(ref.size()));
            const RegionValues noise = RegionRmseNoise(ref_variance, mask);
            row.reference_rmse_noise_sky = noise.sky;
            row.reference_rmse_noise_ground = noise.ground;
        } else {
            ref_variance = Image();
        }
        {
            const RegionLuminance y = MeanLuminance(ref, mask);
            row.reference_mean_sky = y.sky;
            row.reference_mean_ground = y.ground;
        }
        if (config.luminance) {
            row.luminance_scale = config.luminance_scale / view.sun_irradiance;
            row.reference_luminance =
                ScaledLuminance(MeanLuminance(ref, mask), row.luminance_scale);
        }
        // Profiles: along lines of a perspective image (profiles.h).
        if (!transmittance && view.camera.projection == Projection::kPerspective) {
            for (const ProfileLine& line :
                 ViewProfileLines(view, config.width, config.height,
                                  config.atmosphere.bottom_radius, config.atmosphere.top_radius)) {
                CompareRow::Profile profile;
                profile.line = line;
                profile.reference = ProfileLuminance(ref, line);
                if (ref_variance.size() > 0)
                    profile.reference_sigma = ProfileSigma(ref_variance, line);
                row.profiles.push_back(std::move(profile));
            }
        }
        if (spectral_reference) {
            bool cached_rgb = false;
            row.rgb_reference_image =
                rgb_reference.Render(view, &row.rgb_reference_seconds, &cached_rgb);
        }
        const Image& rgb_ref = row.rgb_reference_image;
        row.reference_png = (fs::path("images") / FileStem(view.name) / "reference.png").string();
        if (config.show_progress) {
            std::fprintf(stderr, "%-22s reference (%s) %s %.3f s", view.name.c_str(),
                         config.reference_model.c_str(), row.reference_source.c_str(),
                         row.reference_seconds);
            if (!row.reference_provenance.empty()) {
                std::fprintf(stderr, " from %s", row.reference_provenance.c_str());
            }
            if (row.reference_noise >= 0.0) {
                const bool above = noise_target && row.reference_noise > mc.noise_target;
                std::fprintf(stderr, "  noise %.4f at %lld spp%s", row.reference_noise,
                             static_cast<long long>(row.reference_spp),
                             !above ? ""
                             : row.reference_source == "shipped"
                                 ? " (above the target, at the cap or more)"
                                 : " (cap reached, above the target)");
            }
            std::fprintf(stderr, "\n");
        }
        for (size_t m = 0; m < result.models.size(); ++m) {
            const std::string& name = result.models[m];
            const std::string stem = FileStem(name);
            CompareCell cell;
            cell.image = renderers[m]->Render(view, &cell.render_seconds, &cell.cached);
            const Image& img = cell.image;
            FlipResult flip =
                transmittance ? LdrFlip(ref, img, config.flip) : HdrFlip(ref, img, config.flip);
            const RmseResult rmse = ComputeRmse(ref, img);
            cell.flip = flip.mean;
            cell.rmse = rmse.overall;
            const RegionValues flip_regions = RegionMean(flip.map, mask);
            const RegionValues rmse_regions = RegionRmse(ref, img, mask);
            cell.flip_sky = flip_regions.sky;
            cell.flip_ground = flip_regions.ground;
            cell.rmse_sky = rmse_regions.sky;
            cell.rmse_ground = rmse_regions.ground;
            if (config.luminance) {
                cell.luminance = ScaledLuminance(MeanLuminance(img, mask), row.luminance_scale);
            }
            if (spectral_reference)
                cell.flip_rgb_reference = HdrFlip(rgb_ref, img, config.flip).mean;
            for (CompareRow::Profile& profile : row.profiles) {
                profile.models.push_back(ProfileLuminance(img, profile.line));
            }
            cell.within_noise = row.reference_noise >= 0.0 && cell.flip <= row.reference_noise;
            cell.flip_map = std::move(flip.map);
            cell.validity_note = ValidityNote(GetModelInfo(result.model_names[m]).capabilities,
                                              view, config.atmosphere);
            cell.image_png = (fs::path("images") / FileStem(view.name) / (stem + ".png")).string();
            cell.flip_png =
                (fs::path("errors") / FileStem(view.name) / (stem + "-flip.png")).string();
            cell.rmse_png =
                (fs::path("errors") / FileStem(view.name) / (stem + "-rmse.png")).string();
            if (config.show_progress) {
                std::fprintf(stderr, "%-22s %-20s %s %.3f s  FLIP %.6f  RMSE %.8f%s",
                             view.name.c_str(), name.c_str(), cell.cached ? "cached" : "rendered",
                             cell.render_seconds, cell.flip, cell.rmse,
                             cell.validity_note.empty() ? "" : "  (outside validity)");
                if (spectral_reference) {
                    std::fprintf(stderr, "  FLIP vs RGB reference %.6f", cell.flip_rgb_reference);
                }
                std::fprintf(stderr, "\n");
            }
            row.cells.push_back(std::move(cell));
        }
        row.reference_image = std::move(ref);
        result.rows.push_back(std::move(row));
    }
    for (const auto& r : renderers) {
        r->LoadPrepareRecord();
        result.prepare_seconds.push_back(r->prepare_seconds());
        result.prepared.push_back(r->prepared());
        result.table_bytes.push_back(r->table_bytes());
    }
    result.reference_prepare_seconds = reference.prepare_seconds() + reference_b.prepare_seconds();
    const std::string source_dir = DefaultSourceDir();
    for (size_t m = 0; m < result.model_names.size(); ++m) {
        // Once per registered model (variants share their model's code).
        const auto first =
            std::find(result.model_names.begin(), result.model_names.end(), result.model_names[m]);
        if (first - result.model_names.begin() == static_cast<std::ptrdiff_t>(m)) {
            result.loc.push_back(CountModelLoc(source_dir, result.model_names[m]));
        }
    }
    result.loc.push_back(CountModelLoc(source_dir, config.reference_model));

    result.reference_noise_table = split_reference || noise_target || shipped;
    result.reference_noise_target = noise_target ? mc.noise_target : 0.0;
    result.total_seconds = SecondsSince(start);
    return result;
}

void WriteCompareImages(const CompareConfig& config, const CompareResult& r) {
    const fs::path out(config.output_dir);
    for (const CompareRow& row : r.rows) {
        const fs::path image_dir = out / "images" / FileStem(row.view);
        const fs::path error_dir = out / "errors" / FileStem(row.view);
        fs::create_directories(image_dir);
        fs::create_directories(error_dir);
        if (row.rgb_reference_image.size() > 0) {
            WriteImages(row.rgb_reference_image, image_dir, "reference-rgb", row.exposure,
                        config.write_npy);
        }
        WriteImages(row.reference_image, image_dir, "reference", row.exposure, config.write_npy);
        for (size_t m = 0; m < row.cells.size() && m < r.models.size(); ++m) {
            const CompareCell& cell = row.cells[m];
            const std::string stem = FileStem(r.models[m]);
            WriteImages(cell.image, image_dir, stem, row.exposure, config.write_npy);
            WriteColorMappedPng(cell.flip_map, cell.image.width(), cell.image.height(),
                                (error_dir / (stem + "-flip.png")).string());
            const Image abs_error = AbsoluteErrorImage(row.reference_image, cell.image);
            WriteImage(abs_error, (error_dir / (stem + "-rmse.exr")).string());
            WriteImage(abs_error, (error_dir / (stem + "-rmse.png")).string(), row.exposure);
        }
    }
}

void WriteCompareTables(const CompareConfig& config, const CompareResult& r) {
    const fs::path out(config.output_dir);
    fs::create_directories(out);
    // Tables (thesis Appendix A/B, or C/D for transmittance) and times.
    std::vector<std::string> labels;
    std::vector<std::vector<double>> flips, rmses;
    std::vector<double> flip_noise, rmse_noise;
    for (const CompareRow& row : r.rows) {
        labels.push_back(row.label);
        flip_noise.push_back(row.reference_noise);
        rmse_noise.push_back(row.reference_rmse_noise);
        std::vector<double> flip, rmse;
        for (const CompareCell& c : row.cells) {
            flip.push_back(c.flip);
            rmse.push_back(c.rmse);
        }
        flips.push_back(flip);
        rmses.push_back(rmse);
    }
    WriteMetricCsv((out / "flip.csv").string(), "FLIP errors", labels, r.models, flips, flip_noise);
    WriteMetricCsv((out / "rmse.csv").string(), "RMSE errors", labels, r.models, rmses, rmse_noise);
    // Sky and ground apart (issue 33 item 2): flip.csv's layout over each
    // region's pixels; ties within the region's reference noise where it is
    // measured, else the whole image's.
    for (const bool ground : {false, true}) {
        std::vector<std::vector<double>> f, e;
        std::vector<double> fn, en;
        for (const CompareRow& row : r.rows) {
            std::vector<double> fr, er;
            for (const CompareCell& c : row.cells) {
                fr.push_back(ground ? c.flip_ground : c.flip_sky);
                er.push_back(ground ? c.rmse_ground : c.rmse_sky);
            }
            f.push_back(fr);
            e.push_back(er);
            const double noise = ground ? row.reference_noise_ground : row.reference_noise_sky;
            fn.push_back(noise >= 0.0 ? noise : row.reference_noise);
            en.push_back(ground ? row.reference_rmse_noise_ground : row.reference_rmse_noise_sky);
        }
        const std::string region = ground ? "ground" : "sky";
        WriteMetricCsv((out / ("flip_" + region + ".csv")).string(), "FLIP errors (" + region + ")",
                       labels, r.models, f, fn);
        WriteMetricCsv((out / ("rmse_" + region + ".csv")).string(), "RMSE errors (" + region + ")",
                       labels, r.models, e, en);
    }
    {
        // The reference's noise and mean per region (empty: not measured, or no pixels).
        TextOutput f((out / "reference_noise_regions.csv").string());
        f << "view,sky_pixels,ground_pixels,flip_noise,flip_noise_sky,flip_noise_ground,"
             "rmse_noise,rmse_noise_sky,rmse_noise_ground,mean_luminance_sky,"
             "mean_luminance_ground\n";
        auto number = [](double v, bool known) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.8g", v);
            return known && std::isfinite(v) ? std::string(buf) : std::string();
        };
        for (const CompareRow& row : r.rows) {
            f << row.label << "," << row.sky_pixels << "," << row.ground_pixels << ","
              << number(row.reference_noise, row.reference_noise >= 0.0) << ","
              << number(row.reference_noise_sky, row.reference_noise_sky >= 0.0) << ","
              << number(row.reference_noise_ground, row.reference_noise_ground >= 0.0) << ","
              << number(row.reference_rmse_noise, row.reference_rmse_noise >= 0.0) << ","
              << number(row.reference_rmse_noise_sky, row.reference_rmse_noise_sky >= 0.0) << ","
              << number(row.reference_rmse_noise_ground, row.reference_rmse_noise_ground >= 0.0)
              << "," << number(row.reference_mean_sky, row.sky_pixels > 0) << ","
              << number(row.reference_mean_ground, row.ground_pixels > 0) << "\n";
        }
        f.Commit();
    }
    if (config.luminance) {
        // Mean photopic luminance (cd m^-2) over the image and each region.
        TextOutput f((out / "luminance.csv").string());
        f << "view,region,reference";
        for (const std::string& m : r.models) f << "," << m;
        f << "\n";
        for (const CompareRow& row : r.rows) {
            for (const char* region : {"all", "sky", "ground"}) {
                const std::string g = region;
                auto pick = [&](const CompareLuminance& l) {
                    const double v = g == "all" ? l.all : g == "sky" ? l.sky : l.ground;
                    char buf[32];
                    std::snprintf(buf, sizeof buf, "%.8g", v);
                    return std::isfinite(v) ? std::string(buf) : std::string();
                };
                f << row.label << "," << g << "," << pick(row.reference_luminance);
                for (const CompareCell& c : row.cells) f << "," << pick(c.luminance);
                f << "\n";
            }
        }
        f.Commit();
    }
    WriteRegimesCsv((out / "regimes.csv").string(), config, r);
    if (r.reference_noise_table) {
        // source: rendered, cached or shipped (then provenance: its provenance.json).
        TextOutput f((out / "reference_noise.csv").string());
        f << "view,reference_noise_flip,half_spp,noise_target,source,provenance\n";
        for (const CompareRow& row : r.rows) {
            std::string provenance = row.reference_provenance;
            for (char& c : provenance) c = c == ',' ? ';' : c;
            f << row.view << "," << row.reference_noise << "," << row.reference_spp / 2 << ","
              << r.reference_noise_target << "," << row.reference_source << "," << provenance
              << "\n";
        }
        f.Commit();
    }
    if (!config.reference_wavelengths.empty()) {
        // What RGB costs: each model against the spectral and the RGB reference.
        TextOutput f((out / "rgb_cost.csv").string());
        f << "view,model,flip_spectral_reference,flip_rgb_reference,difference\n";
        for (const CompareRow& row : r.rows) {
            for (size_t m = 0; m < r.models.size(); ++m) {
                const CompareCell& c = row.cells[m];
                f << row.view << "," << r.models[m] << "," << c.flip << "," << c.flip_rgb_reference
                  << "," << c.flip - c.flip_rgb_reference << "\n";
            }
        }
        f.Commit();
    }
    {
        TextOutput f((out / "times.csv").string());
        f << "view,model,render_seconds,cached,prepare_seconds\n";
        for (const CompareRow& row : r.rows) {
            f << row.view << ",reference:" << config.reference_model << "," << row.reference_seconds
              << "," << (row.reference_cached ? 1 : 0) << "," << r.reference_prepare_seconds
              << "\n";
            for (size_t m = 0; m < r.models.size(); ++m) {
                f << row.view << "," << r.models[m] << "," << row.cells[m].render_seconds << ","
                  << (row.cells[m].cached ? 1 : 0) << "," << r.prepare_seconds[m] << "\n";
            }
        }
        f.Commit();
    }
    WriteAccuracyCostCsv((out / "accuracy_cost.csv").string(), config, r);
    WriteCompareReport((out / "index.html").string(), config, r);
}

}  // namespace atmos
