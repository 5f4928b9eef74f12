// atmos model `hillaire`: table construction, per-frame tables, bake.
// See hillaire.h for the source, equations and deviations.
#include "models/hillaire.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/gpu_passes.h"
#include "io/output_path.h"
#include "io/raw_tables.h"
#include "io/table_io.h"
#include "models/hillaire_stages.h"
#include "models/hillaire_wide.h"
#include "models/option_json.h"
#include "models/order_check.h"
#include "render/stages.h"
#include "render/wide.h"

namespace atmos {

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
        "(EGSR); Leenman's 2025 thesis sections 5.2, 11.2.4, 12.1.1; Bruneton's 2017 "
        "implementation notes transmittance mapping";
    info.summary =
        "transmittance + multiple-scattering LUTs; per-frame sky-view and aerial-perspective "
        "tables inside the atmosphere, ray march outside";
    info.capabilities.multiple_scattering = true;
    info.capabilities.precomputed = true;
    info.options = OptionRows().Specs();
    info.capabilities.wide_channels = true;
    info.capabilities.shader = "hillaire";
    info.capabilities.validity_notes = {
        "optically thick atmospheres are past the method's limit: Prepare warns on stderr when "
        "the multiple-scattering transfer f_ms exceeds 0.5 (the series 1 / (1 - f_ms) then "
        "over-brightens: +42 % to +110 % measured)"};
    info.thesis_name = "Hillaire";
    info.thesis_lines = 208;
    // Measured: the zenith transmittance from the ground against its own at
    // Earth (docs/models/hillaire.md "Validity domain"): +1.8 % at 52.8 column
    // heights, +2.3 % at 61.6, T = 1 on the giant planet.
    info.domain.max_shell_heights = 55.0;
    info.domain.shell_heights_reason =
        "the tables' fixed ray-march steps (transmittance 40) span the whole shell and step "
        "over the air near the ground (zenith transmittance +2.3 % at 62 heights, 1 on a 1e9 m "
        "shell)";
    return info;
}

const OptionTable<HillaireOptions>& HillaireModel::OptionRows() {
    using O = HillaireOptions;
    static const auto table =
        OptionTable<O>()
            .Integer("steps", &O::steps, 1, 1e5, "",
                     "ray-march steps for cameras outside the atmosphere")
            .Integer("sky-view-steps", &O::sky_view_steps, 1, 1e5, "",
                     "ray-march steps of each sky-view texel")
            .Integer("transmittance-steps", &O::transmittance_steps, 1, 1e5, "",
                     "optical-depth steps of the transmittance table")
            .ShapesTables()
            .Real("ap-km-per-slice", &O::ap_km_per_slice, 0.001, 1e4, "km",
                  "aerial-perspective depth scale (km per slice)")
            .Integer("ap-steps-per-slice", &O::ap_steps_per_slice, 1, 1e4, "",
                     "aerial-perspective march segments per slice")
            .Real("segment-offset", &O::segment_offset, 0, 1, "",
                  "position of the sample inside each march segment (0.5: midpoint; 0.3: the "
                  "paper's demo)")
            .ShapesTables()  // the multiple-scattering table's march (issue 33 item 4)
            .Choice("ground-path", &O::ground_from_ap,
                    {{"aerial-perspective", true}, {"sky-view", false}},
                    "in-scatter and transmittance of ground rays (camera inside): from the aerial-"
                    "perspective volume or the sky-view table")
            .Choice("sample-path", &O::sample_with_tables, {{"table", true}, {"march", false}},
                    "sample: each query through the sky-view table of its altitude and sun (its "
                    "four texels), or the ray march");
    return table;
}

HillaireModel::HillaireModel(const HillaireOptions& options) : info_(StaticInfo()) {
    evaluator_.atm = EarthAtmosphere();
    evaluator_.steps = options.steps;
    sky_view_steps_ = options.sky_view_steps;
    transmittance_steps_ = options.transmittance_steps;
    evaluator_.ap_metres_per_slice = options.ap_km_per_slice * 1000.0;
    ap_steps_per_slice_ = options.ap_steps_per_slice;
    evaluator_.segment_offset = options.segment_offset;
    evaluator_.ground_from_ap = options.ground_from_ap;
    sample_with_tables_ = options.sample_with_tables;
    options_ = options;
}

void HillaireModel::Attach() {
    evaluator_.transmittance = transmittance_.view();
    evaluator_.multiple_scattering = multiple_scattering_.view();
}

void HillaireModel::Prepare(const AtmosphereParameters& atmosphere) {
    WarnOutsideValidityDomain(Info(), atmosphere);  // its declared domain (atmos/model.h)
    ValidateAtmosphere(atmosphere);
    evaluator_.atm = atmosphere;
    // On a device backend the transmittance table stays on the device for the
    // multiple-scattering stage; both come back at the end, and stay on the
    // device for the renders (the model's resident session).
    ResidentScope scope(&resident_);
    StageSession session;
    BuildTransmittance();
    Table transfer;
    BuildMultipleScattering(&transfer);
    session.Download(&transmittance_);
    session.Download(&multiple_scattering_);
    session.Download(&transfer);
    scope.Keep(evaluator_);
    // The series 1 / (1 - f_ms) past its limit (models/order_check.h).
    WarnIfSeriesPastLimit("hillaire", TableMax(transfer));
}

// The evaluator the precomputation stages read: the model's tables, no frame
// tables.
HillaireEvaluator HillaireModel::StageEvaluator() const {
    HillaireEvaluator e = evaluator_;
    e.sky_view = e.ap_scatter = e.ap_transmittance = TableView{};
    return e;
}

// Transmittance table: Bruneton's 2017 implementation notes
// ComputeTransmittanceToTopAtmosphereBoundaryTexture, optical depth by the midpoint rule with
// transmittance_steps_ segments (HillaireTransmittanceStage).
void HillaireModel::BuildTransmittance() {
    transmittance_.Resize(kHillaireTransmittanceWidth, kHillaireTransmittanceHeight, 1, 3);
    HillaireTransmittanceStage stage;
    stage.atm = evaluator_.atm;
    stage.steps = transmittance_steps_;
    stage.out = transmittance_.out();
    RunStage("hillaire/transmittance",
             int64_t{kHillaireTransmittanceWidth} * kHillaireTransmittanceHeight, 64, stage);
    Attach();
}

// Multiple-scattering table (paper section 5.5.2, Eq. 5-10): see hillaire.h
// (HillaireMultipleScatteringStage).
void HillaireModel::BuildMultipleScattering(Table* transfer) {
    multiple_scattering_.Resize(kHillaireMsSize, kHillaireMsSize, 1, 3);
    if (transfer) transfer->Resize(kHillaireMsSize, kHillaireMsSize, 1, 3);
    HillaireMultipleScatteringStage stage;
    stage.e = StageEvaluator();
    stage.e.use_multiple_scattering = false;
    stage.e.multiple_scattering = TableView{};  // not read (the table being built)
    stage.out = multiple_scattering_.out();
    if (transfer) stage.transfer = transfer->out();
    RunStage("hillaire/multiple-scattering", int64_t{kHillaireMsSize} * kHillaireMsSize, 4, stage);
    Attach();
}

void HillaireModel::BuildSkyView(double r, double mu_s, Table* table) const {
    const AtmosphereParameters& atm = evaluator_.atm;
    table->Resize(kHillaireSkyViewWidth, kHillaireSkyViewHeight, 1, 3);
    // The table's rays start at least kHillaireSkyViewMinAltitude above the
    // ground, where its horizon angle is taken (else the texel row just above
    // the horizon would start on the ground and read black).
    HillaireSkyViewStage stage;
    stage.e = StageEvaluator();
    stage.r = Max(r, atm.bottom_radius + kHillaireSkyViewMinAltitude);
    stage.sun = Vec3d(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    stage.steps = sky_view_steps_;
    stage.out = table->out();
    RunStage("hillaire/sky-view", int64_t{kHillaireSkyViewWidth} * kHillaireSkyViewHeight, 32,
             stage);
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
    StageSession session;  // the model's tables are uploaded once for both stages
    BuildSkyView(r, mu_s, &frame->sky_view);
    if (!with_aerial_perspective) {
        session.Download(&frame->sky_view);
        return frame;
    }

    // Aerial-perspective volume: one cumulative march per screen texel column
    // (HillaireAerialPerspectiveStage).
    frame->base.ap_camera = camera_frame;
    frame->base.ap_aspect = aspect;
    frame->ap_scatter.Resize(kHillaireApSize, kHillaireApSize, kHillaireApSize, 3);
    frame->ap_transmittance.Resize(kHillaireApSize, kHillaireApSize, kHillaireApSize, 3);
    HillaireAerialPerspectiveStage stage;
    stage.e = StageEvaluator();
    stage.camera = camera_frame;
    stage.sun = sun;
    stage.aspect = aspect;
    stage.metres_per_slice = evaluator_.ap_metres_per_slice;
    stage.steps_per_slice = ap_steps_per_slice_;
    stage.scatter = frame->ap_scatter.out();
    stage.transmittance = frame->ap_transmittance.out();
    RunStage("hillaire/aerial-perspective", int64_t{kHillaireApSize} * kHillaireApSize, 4, stage);
    session.Download(&frame->sky_view);
    session.Download(&frame->ap_scatter);
    session.Download(&frame->ap_transmittance);
    return frame;
}

void HillaireModel::Render(const RenderRequest& request, Image* out) const {
    if (!transmittance_.size()) Fail("model hillaire: Prepare() was not called");
    const PixelSetup setup = MakePixelSetup(request, evaluator_.atm);
    // The model's tables stay on the device; the frame's are dropped after.
    ResidentScope scope(&resident_);
    scope.Keep(evaluator_);
    const std::unique_ptr<HillaireFrame> frame = BuildFrame(
        request.view.camera, request.view.sun_direction,
        static_cast<double>(request.width) / request.height,
        // The volume is a perspective frustum: other projections
        // take the ground from the sky-view table, as sample does.
        evaluator_.ground_from_ap && request.view.camera.projection == Projection::kPerspective);
    out->Resize(request.width, request.height);
    RenderImage(frame->Evaluator(), setup, out->View(), request.show_progress);
}

std::vector<SampleAnswer> HillaireModel::Sample(const std::vector<SampleQuery>& queries) const {
    if (!transmittance_.size()) Fail("model hillaire: Prepare() was not called");
    const AtmosphereParameters& atm = evaluator_.atm;
    ResidentScope scope(&resident_);
    scope.Keep(evaluator_);
    if (!sample_with_tables_) return SampleAll(evaluator_, atm.bottom_radius, queries);
    // The table path (issue 33 item 1): each query reads the sky-view table of
    // its own camera and sun, computing only the four texels its lookup reads
    // (HillaireEvaluator::SkyView), so that its answer is the one a render's
    // frame table gives and does not depend on the other queries of the batch.
    // (It replaced one full table per (altitude, mu_s) group with an automatic
    // switch to the march for scattered queries, which made an answer depend
    // on the batch.) Cost: 4 x sky-view-steps march steps per query.
    HillaireEvaluator e = evaluator_;
    e.per_query_sky_view_steps = sky_view_steps_;
    return SampleAll(e, atm.bottom_radius, queries);
}

// --- Wide channel batches (models/hillaire_wide.h) ---------------------------

void HillaireModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                                const BatchPrepare&) {
    for (const AtmosphereParameters& a : batches) {
        WarnOutsideValidityDomain(Info(), a);
        ValidateAtmosphere(a);
    }
    const WideCoefficients w = MakeWideCoefficients(batches);
    const int n = w.channels;
    // The stages read the model's evaluator without tables, as Prepare()'s.
    HillaireWideEvaluator e;
    e.narrow = StageEvaluator();
    e.narrow.atm = batches[0];
    e.w = w;
    Table transmittance(kHillaireTransmittanceWidth, kHillaireTransmittanceHeight, 1, n);
    HillaireWideTransmittanceStage t;
    t.atm = batches[0];
    t.w = w;
    t.steps = transmittance_steps_;
    t.out = transmittance.data();
    RunCpuStage("hillaire/wide-transmittance",
                int64_t{kHillaireTransmittanceWidth} * kHillaireTransmittanceHeight, 64,
                [&t](int64_t i) { t(i); });
    e.narrow.transmittance = transmittance.view();
    Table multiple_scattering(kHillaireMsSize, kHillaireMsSize, 1, n);
    Table transfer(kHillaireMsSize, kHillaireMsSize, 1, n);
    HillaireWideMultipleScatteringStage ms;
    ms.e = e;
    ms.e.narrow.use_multiple_scattering = false;
    ms.e.narrow.multiple_scattering = TableView{};  // not read (the table being built)
    ms.out = multiple_scattering.data();
    ms.transfer = transfer.data();
    RunCpuStage("hillaire/wide-multiple-scattering", int64_t{kHillaireMsSize} * kHillaireMsSize, 4,
                [&ms](int64_t i) { ms(i); });
    wide_atm_ = batches[0];
    wide_ = w;
    wide_transmittance_ = std::move(transmittance);
    wide_multiple_scattering_ = std::move(multiple_scattering);
    WarnIfSeriesPastLimit("hillaire", TableMax(transfer));
}

namespace {

// The wide evaluator of a model's wide tables (no frame tables).
HillaireWideEvaluator WideEvaluator(const HillaireEvaluator& base, const AtmosphereParameters& atm,
                                    const WideCoefficients& w, const Table& transmittance,
                                    const Table& multiple_scattering) {
    HillaireWideEvaluator e;
    e.narrow = base;
    e.narrow.atm = atm;
    e.narrow.transmittance = transmittance.view();
    e.narrow.multiple_scattering = multiple_scattering.view();
    e.narrow.sky_view = e.narrow.ap_scatter = e.narrow.ap_transmittance = TableView{};
    e.narrow.per_query_sky_view_steps = 0;
    e.w = w;
    return e;
}

}  // namespace

void HillaireModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    if (!wide_transmittance_.size()) {
        Fail("model hillaire: PrepareWide() must run before RenderWide()");
    }
    const int n = wide_.channels;
    const WidePixelSetup setup = MakeWidePixelSetup(request, wide_atm_, wide_);
    // The frame's tables as BuildFrame builds them, n channels.
    const HillaireWideEvaluator stage_e =
        WideEvaluator(evaluator_, wide_atm_, wide_, wide_transmittance_, wide_multiple_scattering_);
    HillaireWideEvaluator e = stage_e;
    Table sky_view, ap_scatter, ap_transmittance;
    const Camera& camera_frame = request.view.camera;
    const Vec3d camera = camera_frame.position;
    const Vec3d sun = request.view.sun_direction;
    const double r = Length(camera);
    if (r <= wide_atm_.top_radius) {
        const double mu_s = ClampCosine(Dot(sun, camera) / r);
        sky_view.Resize(kHillaireSkyViewWidth, kHillaireSkyViewHeight, 1, n);
        HillaireWideSkyViewStage sv;
        sv.e = stage_e;
        sv.r = Max(r, wide_atm_.bottom_radius + kHillaireSkyViewMinAltitude);
        sv.sun = Vec3d(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        sv.steps = sky_view_steps_;
        sv.out = sky_view.data();
        RunCpuStage("hillaire/wide-sky-view",
                    int64_t{kHillaireSkyViewWidth} * kHillaireSkyViewHeight, 32,
                    [&sv](int64_t i) { sv(i); });
        e.narrow.sky_view = sky_view.view();
        // The volume is a perspective frustum (Render).
        if (evaluator_.ground_from_ap && camera_frame.projection == Projection::kPerspective) {
            const double aspect = static_cast<double>(request.width) / request.height;
            ap_scatter.Resize(kHillaireApSize, kHillaireApSize, kHillaireApSize, n);
            ap_transmittance.Resize(kHillaireApSize, kHillaireApSize, kHillaireApSize, n);
            HillaireWideAerialPerspectiveStage ap;
            ap.e = stage_e;
            ap.camera = camera_frame;
            ap.sun = sun;
            ap.aspect = aspect;
            ap.metres_per_slice = evaluator_.ap_metres_per_slice;
            ap.steps_per_slice = ap_steps_per_slice_;
            ap.scatter = ap_scatter.data();
            ap.transmittance = ap_transmittance.data();
            RunCpuStage("hillaire/wide-aerial-perspective",
                        int64_t{kHillaireApSize} * kHillaireApSize, 4, [&ap](int64_t i) { ap(i); });
            e.narrow.ap_camera = camera_frame;
            e.narrow.ap_aspect = aspect;
            e.narrow.ap_scatter = ap_scatter.view();
            e.narrow.ap_transmittance = ap_transmittance.view();
        }
    }
    RenderWideImage(e, setup, values);
}

std::vector<float> HillaireModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    if (!wide_transmittance_.size()) {
        Fail("model hillaire: PrepareWide() must run before SampleWide()");
    }
    HillaireWideEvaluator e =
        WideEvaluator(evaluator_, wide_atm_, wide_, wide_transmittance_, wide_multiple_scattering_);
    // As Sample: the table path computes each query's four sky-view texels.
    if (sample_with_tables_) e.narrow.per_query_sky_view_steps = sky_view_steps_;
    return SampleAllWide(e, wide_atm_.bottom_radius, queries);
}

// --- Bake -----------------------------------------------------------------

namespace {
constexpr const char* kBakeJson = "hillaire.json";
constexpr const char* kTransmittanceExr = "transmittance.exr";
constexpr const char* kMultipleScatteringExr = "multiple_scattering.exr";
}  // namespace

namespace {

// The #defines shaders/hillaire.glsl reads (DIR/shaders/hillaire_constants.glsl).
std::string HillaireGlslConstants(const AtmosphereParameters& a, const HillaireOptions& o) {
    std::ostringstream s;
    BeginGlslConstants(
        s,
        "// Generated by `atmos bake hillaire`: the constants of these tables for\n"
        "// shaders/common.glsl and shaders/hillaire.glsl (include this first). Lengths in\n"
        "// metres.\n",
        a);
    s << "#define ATMOS_TRANSMITTANCE_WIDTH " << kHillaireTransmittanceWidth << "\n";
    s << "#define ATMOS_TRANSMITTANCE_HEIGHT " << kHillaireTransmittanceHeight << "\n";
    s << "#define ATMOS_STEPS " << o.steps << "\n";
    s << "#define ATMOS_TRANSMITTANCE_STEPS " << o.transmittance_steps << "\n";
    s << "#define ATMOS_SKY_VIEW_STEPS " << o.sky_view_steps << "\n";
    s << "#define ATMOS_AP_STEPS_PER_SLICE " << o.ap_steps_per_slice << "\n";
    s << "#define ATMOS_AP_METRES_PER_SLICE " << o.ap_km_per_slice * 1000.0 << "\n";
    s << "#define ATMOS_SEGMENT_OFFSET " << o.segment_offset << "\n";
    s << "#define ATMOS_GROUND_FROM_AP " << (o.ground_from_ap ? 1 : 0) << "\n";
    return s.str();
}

// The GPU passes that compute the two tables from the constants
// (shaders/hillaire_precompute.glsl; io/gpu_passes.h): the transmittance
// table, then the multiple-scattering table from it.
GpuPrecompute HillaireGpuPrecompute() {
    GpuPrecompute p;
    p.shaders = {"shaders/hillaire_constants.glsl", "shaders/common.glsl", "shaders/hillaire.glsl",
                 "shaders/hillaire_precompute.glsl"};
    p.targets["transmittance"] = {kHillaireTransmittanceWidth, kHillaireTransmittanceHeight, 1, 4};
    p.targets["multiple_scattering"] = {kHillaireMsSize, kHillaireMsSize, 1, 4};
    GpuPass t;
    t.name = "transmittance";
    t.entry = "ATMOS_HILLAIRE_TRANSMITTANCE";
    t.target = "transmittance";
    GpuPass ms;
    ms.name = "multiple_scattering";
    ms.entry = "ATMOS_HILLAIRE_MULTIPLE_SCATTERING";
    ms.target = "multiple_scattering";
    ms.inputs["atmos_transmittance_texture"] = "transmittance";
    p.passes = {t, ms};
    return p;
}

}  // namespace

namespace {
// The tables a bake writes raw (tables.f32/.f16), in their order.
std::vector<RawTable> RawTables(const Table& transmittance, const Table& multiple_scattering) {
    return {{"transmittance", &transmittance}, {"multiple_scattering", &multiple_scattering}};
}
}  // namespace

int64_t HillaireModel::TableBytes() const {
    if (!transmittance_.size()) return -1;
    return static_cast<int64_t>(
        RawTablesFloat32Bytes(RawTables(transmittance_, multiple_scattering_)));
}

void HillaireModel::Bake(const std::string& directory) const {
    if (!transmittance_.size()) Fail("model hillaire: nothing to bake (Prepare() was not called)");
    namespace fs = std::filesystem;
    WriteTableExr(transmittance_, (fs::path(directory) / kTransmittanceExr).string());
    WriteTableExr(multiple_scattering_, (fs::path(directory) / kMultipleScatteringExr).string());
    nlohmann::json j;
    j["model"] = "hillaire";
    j["source"] = info_.citation;
    j["format_version"] = 2;  // 2: "options" from the option table
    j["options"] = nlohmann::json::parse(
        OptionsJson(OptionRows().Specs(), OptionRows().Values(options_)).dump());
    j["tables"] = nlohmann::json::array(
        {{{"name", "transmittance"},
          {"file", kTransmittanceExr},
          {"width", kHillaireTransmittanceWidth},
          {"height", kHillaireTransmittanceHeight},
          {"depth", 1},
          {"channels", 3},
          {"content", "RGB transmittance from (r, mu) to the top of the atmosphere"},
          {"mapping",
           "Bruneton's 2017 implementation notes GetTransmittanceTextureUvFromRMu: H = sqrt(top^2 "
           "- bottom^2), rho = "
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
    j["raw"] = nlohmann::json::parse(
        WriteRawTables(directory, RawTables(transmittance_, multiple_scattering_)).dump());
    j["shaders"] = nlohmann::json::parse(
        WriteGlslConstants(directory, "hillaire", HillaireGlslConstants(evaluator_.atm, options_))
            .dump());
    j["gpu_precompute"] = nlohmann::json::parse(GpuPrecomputeJson(HillaireGpuPrecompute()).dump());
    WriteFileAtomically((fs::path(directory) / kBakeJson).string(), j.dump(2) + "\n");
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
    if (!j.contains("format_version") || j["format_version"] != 2) {
        Fail(json_path.string(), ": baked by another version of atmos (format_version ",
             j.contains("format_version") ? j["format_version"].dump() : "missing",
             ", expected 2): bake it again");
    }
    CheckBakedOptions(json_path.string(), nlohmann::ordered_json::parse(j["options"].dump()),
                      OptionRows().Specs(), OptionRows().Values(options_));
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
    Attach();
}

}  // namespace atmos
