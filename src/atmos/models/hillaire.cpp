// atmos model `hillaire`: table construction, per-frame tables, bake.
// See hillaire.h for the source, equations and deviations.
#include "models/hillaire.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/table_io.h"

namespace atmos {

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Vec4f ToTexel(const Vec3d& v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), 0.0f};
}

}  // namespace

HillaireEvaluator HillaireFrame::Evaluator() const {
    HillaireEvaluator e = base;
    e.sky_view = sky_view.size() ? sky_view.view() : TableView{};
    e.ap_scatter = ap_scatter.size() ? ap_scatter.view() : TableView{};
    e.ap_transmittance = ap_transmittance.size() ? ap_transmittance.view() : TableView{};
    return e;
}

ModelInfo HillaireModel::StaticInfo() {
    ModelInfo info;
    info.name = "hillaire";
    info.title = "Hillaire 2020 (sky-view, aerial perspective, multiple-scattering LUTs)";
    info.citation =
        "Hillaire 2020, A Scalable and Production Ready Sky and Atmosphere Rendering Technique "
        "(EGSR); seed 003 sections 5.2, 11.2.4, 12.1.1; seed 004 transmittance mapping";
    info.summary =
        "transmittance + multiple-scattering LUTs; per-frame sky-view and aerial-perspective "
        "tables inside the atmosphere, ray march outside";
    info.capabilities.multiple_scattering = true;
    info.capabilities.precomputed = true;
    using T = ModelOptionSpec::Type;
    info.options = {
        {"steps",
         T::kInteger,
         "40",
         "ray-march steps for cameras outside the atmosphere",
         1,
         1e5,
         {}},
        {"sky-view-steps", T::kInteger, "30", "ray-march steps of each sky-view texel", 1, 1e5, {}},
        {"transmittance-steps",
         T::kInteger,
         "40",
         "optical-depth steps of the transmittance table",
         1,
         1e5,
         {}},
        {"ap-km-per-slice",
         T::kReal,
         "4",
         "aerial-perspective depth scale (km per slice)",
         0.001,
         1e4,
         {}},
        {"ap-steps-per-slice",
         T::kInteger,
         "4",
         "aerial-perspective march segments per slice",
         1,
         1e4,
         {}},
        {"segment-offset",
         T::kReal,
         "0.3",
         "position of the sample inside each march segment (0.3: the paper's demo, 0.5: "
         "midpoint)",
         0,
         1,
         {}},
        {"ground-path",
         T::kChoice,
         "aerial-perspective",
         "in-scatter and transmittance of ground rays (camera inside): from the aerial-"
         "perspective volume or the sky-view table",
         0,
         0,
         {"aerial-perspective", "sky-view"}},
        {"sample-path",
         T::kChoice,
         "table",
         "sample: sky-view table per (altitude, sun) group, or ray march everything",
         0,
         0,
         {"table", "march"}},
    };
    return info;
}

HillaireModel::HillaireModel(const ModelOptions& options) : info_(StaticInfo()) {
    evaluator_.atm = EarthAtmosphere();
    evaluator_.steps = options.GetInt("steps");
    sky_view_steps_ = options.GetInt("sky-view-steps");
    transmittance_steps_ = options.GetInt("transmittance-steps");
    evaluator_.ap_metres_per_slice = options.GetReal("ap-km-per-slice") * 1000.0;
    ap_steps_per_slice_ = options.GetInt("ap-steps-per-slice");
    evaluator_.segment_offset = options.GetReal("segment-offset");
    evaluator_.ground_from_ap = options.GetText("ground-path") == "aerial-perspective";
    sample_with_tables_ = options.GetText("sample-path") == "table";
}

void HillaireModel::Attach() {
    evaluator_.transmittance = transmittance_.view();
    evaluator_.multiple_scattering = multiple_scattering_.view();
}

void HillaireModel::Prepare(const AtmosphereParameters& atmosphere) {
    ValidateAtmosphere(atmosphere);
    evaluator_.atm = atmosphere;
    auto start = std::chrono::steady_clock::now();
    BuildTransmittance();
    prepare_timings_.transmittance_s = SecondsSince(start);
    start = std::chrono::steady_clock::now();
    BuildMultipleScattering();
    prepare_timings_.multiple_scattering_s = SecondsSince(start);
}

// Transmittance table: seed 004 ComputeTransmittanceToTopAtmosphereBoundaryTexture,
// optical depth by the midpoint rule with transmittance_steps_ segments.
void HillaireModel::BuildTransmittance() {
    const AtmosphereParameters& atm = evaluator_.atm;
    const int n = transmittance_steps_;
    transmittance_.Resize(kHillaireTransmittanceWidth, kHillaireTransmittanceHeight, 1, 3);
    ParallelFor(kHillaireTransmittanceHeight, 1, [&](int64_t j64) {
        const int j = static_cast<int>(j64);
        for (int i = 0; i < kHillaireTransmittanceWidth; ++i) {
            double r, mu;
            HillaireTransmittanceRMu(
                atm, static_cast<double>(i) / (kHillaireTransmittanceWidth - 1),
                static_cast<double>(j) / (kHillaireTransmittanceHeight - 1), &r, &mu);
            const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
            const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
            const double dt = d / n;
            Vec3d tau;
            for (int k = 0; k < n; ++k) {
                const Vec3d p(dir.x * (k + 0.5) * dt, 0.0, r + dir.z * (k + 0.5) * dt);
                tau += Extinction(atm, GetDensities(atm, Length(p) - atm.bottom_radius));
            }
            transmittance_.Set(i, j, 0, ToTexel(Exp(-(tau * dt))));
        }
    });
    Attach();
}

// Multiple-scattering table (paper section 5.5.2, Eq. 5-10): see hillaire.h.
void HillaireModel::BuildMultipleScattering() {
    const AtmosphereParameters& atm = evaluator_.atm;
    HillaireEvaluator e = evaluator_;
    e.use_multiple_scattering = false;
    const double p_u = IsotropicPhase();
    constexpr int kDirs = kHillaireMsSqrtDirections * kHillaireMsSqrtDirections;
    multiple_scattering_.Resize(kHillaireMsSize, kHillaireMsSize, 1, 3);
    ParallelFor(kHillaireMsSize * kHillaireMsSize, 4, [&](int64_t index) {
        const int i = static_cast<int>(index % kHillaireMsSize);  // mu_s
        const int j = static_cast<int>(index / kHillaireMsSize);  // altitude
        const double mu_s = -1.0 + 2.0 * i / (kHillaireMsSize - 1);
        const double r =
            atm.bottom_radius + (atm.top_radius - atm.bottom_radius) * j / (kHillaireMsSize - 1);
        const Vec3d x(0.0, 0.0, r);
        const Vec3d sun(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        Vec3d l_2nd, f_ms;
        for (int k = 0; k < kDirs; ++k) {
            // Stratified uniform directions on the sphere (8 x 8 cells, centres).
            const double a = (k / kHillaireMsSqrtDirections + 0.5) / kHillaireMsSqrtDirections;
            const double b = (k % kHillaireMsSqrtDirections + 0.5) / kHillaireMsSqrtDirections;
            const double phi = 2.0 * kPi * a;
            const double cos_theta = 1.0 - 2.0 * b;
            const double sin_theta = SafeSqrt(1.0 - cos_theta * cos_theta);
            const Vec3d dir(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
            const AtmosphereSegment seg =
                ClipToAtmosphere(x, dir, atm.bottom_radius, atm.top_radius);
            Vec3d L, F, T(1.0);
            if (seg.inside) {
                const double dt = (seg.t_end - seg.t_start) / kHillaireMsSteps;
                for (int s = 0; s < kHillaireMsSteps; ++s) {
                    const Vec3d p = x + dir * (seg.t_start + (s + e.segment_offset) * dt);
                    const double rp = Length(p);
                    const Densities d = GetDensities(atm, rp - atm.bottom_radius);
                    const Vec3d sigma_s =
                        atm.rayleigh_scattering * d.rayleigh + atm.mie_scattering * d.mie;
                    const Vec3d sigma_t = Extinction(atm, d);
                    const Vec3d t_sun = e.SunTransmittance(rp, ClampCosine(Dot(p, sun) / rp));
                    const Vec3d S = sigma_s * t_sun * p_u;
                    const Vec3d step_t = Exp(-sigma_t * dt);
                    for (int c = 0; c < 3; ++c) {
                        const double w = sigma_t[c] > 0.0 ? (1.0 - step_t[c]) / sigma_t[c] : dt;
                        L[c] += T[c] * S[c] * w;
                        F[c] += T[c] * sigma_s[c] * w;
                    }
                    T *= step_t;
                }
            }
            if (seg.hits_ground) L += T * e.GroundReflection(x + dir * seg.t_end, sun);
            l_2nd += L;
            f_ms += F;
        }
        // Uniform sampling of the sphere: int f p_u dw = mean of f.
        l_2nd = l_2nd / static_cast<double>(kDirs);
        f_ms = f_ms / static_cast<double>(kDirs);
        Vec3d psi;
        for (int c = 0; c < 3; ++c) psi[c] = l_2nd[c] / Max(1.0 - f_ms[c], 1e-6);
        multiple_scattering_.Set(i, j, 0, ToTexel(psi));
    });
    Attach();
}

void HillaireModel::BuildSkyView(double r, double mu_s, Table* table) const {
    const HillaireEvaluator& e = evaluator_;
    const AtmosphereParameters& atm = e.atm;
    table->Resize(kHillaireSkyViewWidth, kHillaireSkyViewHeight, 1, 3);
    // The table's rays start at least kHillaireSkyViewMinAltitude above the
    // ground, where its horizon angle is taken (else the texel row just above
    // the horizon would start on the ground and read black).
    r = Max(r, atm.bottom_radius + kHillaireSkyViewMinAltitude);
    const Vec3d camera(0.0, 0.0, r);
    const Vec3d sun(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    const int n = sky_view_steps_;
    ParallelFor(kHillaireSkyViewHeight, 1, [&](int64_t j64) {
        const int j = static_cast<int>(j64);
        for (int i = 0; i < kHillaireSkyViewWidth; ++i) {
            double mu_v, cos_az;
            HillaireSkyViewParams(
                r, atm.bottom_radius, static_cast<double>(i) / (kHillaireSkyViewWidth - 1),
                static_cast<double>(j) / (kHillaireSkyViewHeight - 1), &mu_v, &cos_az);
            const double sin_v = SafeSqrt(1.0 - mu_v * mu_v);
            const Vec3d dir(sin_v * cos_az, sin_v * SafeSqrt(1.0 - cos_az * cos_az), mu_v);
            const AtmosphereSegment seg =
                ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
            Vec3d L, T(1.0);
            if (seg.inside) e.Integrate(camera, dir, sun, seg.t_start, seg.t_end, n, &L, &T);
            table->Set(i, j, 0, ToTexel(L));
        }
    });
}

std::unique_ptr<HillaireFrame> HillaireModel::BuildFrame(const Camera& camera_frame,
                                                         const Vec3d& sun, double aspect,
                                                         bool with_aerial_perspective) const {
    auto frame = std::make_unique<HillaireFrame>();
    frame->base = evaluator_;
    const AtmosphereParameters& atm = evaluator_.atm;
    const Vec3d camera = camera_frame.position;
    const double r = Length(camera);
    if (!(r <= atm.top_radius) || !transmittance_.size()) return frame;  // ray march
    const double mu_s = ClampCosine(Dot(sun, camera) / r);
    auto start = std::chrono::steady_clock::now();
    BuildSkyView(r, mu_s, &frame->sky_view);
    frame->timings.sky_view_s = SecondsSince(start);
    if (!with_aerial_perspective) return frame;

    // Aerial-perspective volume: one cumulative march per screen texel column.
    start = std::chrono::steady_clock::now();
    frame->base.ap_camera = camera_frame;
    frame->base.ap_aspect = aspect;
    const double metres_per_slice = evaluator_.ap_metres_per_slice;
    const int sub = ap_steps_per_slice_;
    frame->ap_scatter.Resize(kHillaireApSize, kHillaireApSize, kHillaireApSize, 3);
    frame->ap_transmittance.Resize(kHillaireApSize, kHillaireApSize, kHillaireApSize, 3);
    Table& scatter = frame->ap_scatter;
    Table& trans = frame->ap_transmittance;
    const HillaireEvaluator& e = evaluator_;
    ParallelFor(kHillaireApSize * kHillaireApSize, 4, [&](int64_t index) {
        const int i = static_cast<int>(index % kHillaireApSize);
        const int j = static_cast<int>(index / kHillaireApSize);
        const double u = (i + 0.5) / kHillaireApSize;
        const double v = (j + 0.5) / kHillaireApSize;
        const double tan_y = camera_frame.tan_half_fov_y;
        const Vec3d dir = Normalize(camera_frame.forward +
                                    camera_frame.right * ((2.0 * u - 1.0) * tan_y * aspect) +
                                    camera_frame.up * ((1.0 - 2.0 * v) * tan_y));
        // The froxel's ray ignores the ground (points below it are taken at
        // the ground): a ground ray's value is interpolated between froxel
        // rays, and a neighbour that stopped at its own ground hit would bias it.
        double t_in = 0.0, t_out = 0.0;
        const bool crosses =
            IntersectSphere(camera, dir, atm.top_radius, &t_in, &t_out) && t_out > 0.0;
        t_in = Max(t_in, 0.0);
        Vec3d L, T(1.0);
        double t_prev = 0.0;
        for (int k = 0; k < kHillaireApSize; ++k) {
            const double t_k = HillaireApSliceDistance(k, metres_per_slice);
            if (crosses) {
                const double ta = Clamp(t_prev, t_in, t_out);
                const double tb = Clamp(t_k, t_in, t_out);
                e.Integrate(camera, dir, sun, ta, tb, sub, &L, &T, true);
            }
            t_prev = t_k;
            scatter.Set(i, j, k, ToTexel(L));
            trans.Set(i, j, k, ToTexel(T));
        }
    });
    frame->timings.aerial_perspective_s = SecondsSince(start);
    return frame;
}

void HillaireModel::Render(const RenderRequest& request, Image* out) const {
    if (!transmittance_.size()) Fail("model hillaire: Prepare() was not called");
    const PixelSetup setup = MakePixelSetup(request, evaluator_.atm);
    const std::unique_ptr<HillaireFrame> frame =
        BuildFrame(request.view.camera, request.view.sun_direction,
                   static_cast<double>(request.width) / request.height, evaluator_.ground_from_ap);
    last_frame_timings_ = frame->timings;
    out->Resize(request.width, request.height);
    RenderImage(frame->Evaluator(), setup, out->View(), request.show_progress);
}

std::vector<SampleAnswer> HillaireModel::Sample(const std::vector<SampleQuery>& queries) const {
    if (!transmittance_.size()) Fail("model hillaire: Prepare() was not called");
    const AtmosphereParameters& atm = evaluator_.atm;
    if (!sample_with_tables_) return SampleAll(evaluator_, atm.bottom_radius, queries);
    // Group the queries by (altitude, mu_s): one sky-view table per group.
    std::map<std::pair<double, double>, std::vector<size_t>> groups;
    for (size_t q = 0; q < queries.size(); ++q) {
        groups[{queries[q].altitude_m, queries[q].mu_s}].push_back(q);
    }
    std::vector<SampleAnswer> answers(queries.size());
    for (const auto& group : groups) {
        const double r = atm.bottom_radius + group.first.first;
        HillaireEvaluator e = evaluator_;
        Table sky_view;
        if (r <= atm.top_radius) {
            BuildSkyView(r, ClampCosine(group.first.second), &sky_view);
            e.sky_view = sky_view.view();
        }
        const std::vector<size_t>& members = group.second;
        ParallelFor(static_cast<int64_t>(members.size()), 64, [&](int64_t k) {
            const size_t q = members[static_cast<size_t>(k)];
            answers[q] = SampleOne(e, atm.bottom_radius, queries[q]);
        });
    }
    return answers;
}

// --- Bake -----------------------------------------------------------------

namespace {
constexpr const char* kBakeJson = "hillaire.json";
constexpr const char* kTransmittanceExr = "transmittance.exr";
constexpr const char* kMultipleScatteringExr = "multiple_scattering.exr";
}  // namespace

void HillaireModel::Bake(const std::string& directory) const {
    if (!transmittance_.size()) Fail("model hillaire: nothing to bake (Prepare() was not called)");
    namespace fs = std::filesystem;
    WriteTableExr(transmittance_, (fs::path(directory) / kTransmittanceExr).string());
    WriteTableExr(multiple_scattering_, (fs::path(directory) / kMultipleScatteringExr).string());
    nlohmann::json j;
    j["model"] = "hillaire";
    j["source"] = info_.citation;
    j["transmittance_steps"] = transmittance_steps_;
    j["tables"] = nlohmann::json::array(
        {{{"name", "transmittance"},
          {"file", kTransmittanceExr},
          {"width", kHillaireTransmittanceWidth},
          {"height", kHillaireTransmittanceHeight},
          {"depth", 1},
          {"channels", 3},
          {"content", "RGB transmittance from (r, mu) to the top of the atmosphere"},
          {"mapping",
           "seed 004 GetTransmittanceTextureUvFromRMu: H = sqrt(top^2 - bottom^2), rho = "
           "sqrt(r^2 - bottom^2), d = distance to top, x_mu = (d - (top - r)) / (rho + H - "
           "(top - r)), x_r = rho / H; u = 0.5/W + x_mu (1 - 1/W), v = 0.5/H + x_r (1 - 1/H)"}},
         {{"name", "multiple_scattering"},
          {"file", kMultipleScatteringExr},
          {"width", kHillaireMsSize},
          {"height", kHillaireMsSize},
          {"depth", 1},
          {"channels", 3},
          {"content",
           "RGB Psi_ms = L_2nd / (1 - f_ms) per unit solar irradiance (Hillaire 2020 Eq. 10); "
           "in-scatter adds (sigma_s_rayleigh + sigma_s_mie) Psi_ms"},
          {"mapping",
           "x = 0.5 mu_s + 0.5, y = (r - bottom) / (top - bottom); u = 0.5/32 + x (1 - 1/32), "
           "v likewise"}}});
    j["atmosphere"] = nlohmann::json::parse(AtmosphereToJson(evaluator_.atm));
    std::ofstream f(fs::path(directory) / kBakeJson);
    f << j.dump(2) << "\n";
    if (!f) Fail("cannot write ", (fs::path(directory) / kBakeJson).string());
}

void HillaireModel::LoadBaked(const std::string& directory,
                              const AtmosphereParameters& atmosphere) {
    namespace fs = std::filesystem;
    const fs::path json_path = fs::path(directory) / kBakeJson;
    std::ifstream f(json_path);
    if (!f) Fail("cannot read ", json_path.string(), " (not a hillaire bake directory?)");
    nlohmann::json j;
    try {
        f >> j;
    } catch (const std::exception& ex) {
        Fail("malformed ", json_path.string(), ": ", ex.what());
    }
    if (!j.contains("model") || j["model"] != "hillaire") {
        Fail(json_path.string(), " was not baked by model hillaire");
    }
    if (!j.contains("atmosphere") ||
        j["atmosphere"] != nlohmann::json::parse(AtmosphereToJson(atmosphere))) {
        Fail(json_path.string(), ": the baked atmosphere differs from the requested one");
    }
    if (!j.contains("transmittance_steps") || j["transmittance_steps"] != transmittance_steps_) {
        Fail(json_path.string(), ": baked with a different --transmittance-steps");
    }
    ValidateAtmosphere(atmosphere);
    evaluator_.atm = atmosphere;
    Table t = ReadTableExr((fs::path(directory) / kTransmittanceExr).string(), 1, 3);
    Table m = ReadTableExr((fs::path(directory) / kMultipleScatteringExr).string(), 1, 3);
    if (t.width() != kHillaireTransmittanceWidth || t.height() != kHillaireTransmittanceHeight ||
        m.width() != kHillaireMsSize || m.height() != kHillaireMsSize) {
        Fail(directory, ": baked tables have unexpected sizes");
    }
    transmittance_ = std::move(t);
    multiple_scattering_ = std::move(m);
    prepare_timings_ = HillairePrepareTimings{};
    Attach();
}

}  // namespace atmos
