// atmos: shipped path-traced references (see shipped_references.h).
#include "harness/shipped_references.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "atmos/error.h"
#include "base/fnv1a.h"
#include "harness/render_cache.h"
#include "io/output_path.h"
#include "models/reference.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kFormat = "atmos-shipped-references 2";

std::string Number(double x) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
}

std::string VecText(const Vec3d& v) { return Number(v.x) + " " + Number(v.y) + " " + Number(v.z); }

std::string SizeText(int width, int height) {
    return std::to_string(width) + "x" + std::to_string(height);
}

Json FingerprintFields(const ReferenceFingerprint& f) {
    Json j;
    j["estimator_version"] = f.estimator_version;
    j["model"] = f.model;
    j["atmosphere"] = f.atmosphere;
    j["atmosphere_hash"] = f.atmosphere_hash;
    j["size"] = SizeText(f.width, f.height);
    j["wavelengths"] = f.wavelengths;
    j["quantity"] = f.quantity;
    return j;
}

// Why a shipped set's fingerprint differs from a run's, one reason per field
// (the atmosphere's label is informative, the view hashes are per view).
std::vector<std::string> FingerprintMismatches(const ReferenceFingerprint& s,
                                               const ReferenceFingerprint& run) {
    std::vector<std::string> why;
    if (s.estimator_version != run.estimator_version) {
        why.push_back("estimator version differs (shipped " + std::to_string(s.estimator_version) +
                      ", this build " + std::to_string(run.estimator_version) + ")");
    }
    if (s.model != run.model)
        why.push_back("reference model options differ (shipped " + s.model + ")");
    if (s.quantity != run.quantity) why.push_back("quantity differs (shipped " + s.quantity + ")");
    if (s.wavelengths != run.wavelengths) {
        why.push_back("wavelengths differ (shipped " + s.wavelengths + ")");
    }
    if (s.width != run.width || s.height != run.height) {
        why.push_back("size differs (shipped " + SizeText(s.width, s.height) + ")");
    }
    if (s.atmosphere_hash != run.atmosphere_hash) {
        why.push_back("atmosphere differs (shipped " + s.atmosphere + ")");
    }
    return why;
}

// One JSON text: top-level fields a line, the fingerprint indented, a view a line.
std::string ProvenanceText(const Json& fingerprint, const std::vector<Json>& views) {
    std::string fp = fingerprint.dump(2);
    for (size_t i = 0; (i = fp.find('\n', i)) != std::string::npos; i += 3)
        fp.replace(i, 1, "\n  ");
    std::string text = "{\n  \"format\": " + Json(kFormat).dump() + ",\n  \"fingerprint\": " + fp +
                       ",\n  \"views\": [";
    for (size_t i = 0; i < views.size(); ++i) {
        text += (i ? ",\n    " : "\n    ") + views[i].dump();
    }
    return text + (views.empty() ? "]\n}\n" : "\n  ]\n}\n");
}

template <typename T>
T Field(const Json& j, const char* key, const std::string& where) {
    if (!j.is_object() || !j.contains(key)) Fail(where, ": missing field '", key, "'");
    try {
        return j.at(key).get<T>();
    } catch (const std::exception&) {
        Fail(where, ": field '", key, "' has the wrong type");
    }
}

}  // namespace

std::string HashText(const std::string& text) { return "fnv1a64:" + Fnv1aHex(Fnv1a64(text)); }

std::string ViewFingerprintText(const View& view) {
    std::string s = "view " + view.name + "\n";
    s += "camera.position " + VecText(view.camera.position) + "\n";
    s += "camera.forward " + VecText(view.camera.forward) + "\n";
    s += "camera.right " + VecText(view.camera.right) + "\n";
    s += "camera.up " + VecText(view.camera.up) + "\n";
    s += "camera.tan_half_fov_y " + Number(view.camera.tan_half_fov_y) + "\n";
    s += "sun_direction " + VecText(view.sun_direction) + "\n";
    s += "sun_irradiance " + Number(view.sun_irradiance) + "\n";
    return s;
}

ReferenceFingerprint MakeReferenceFingerprint(const std::string& model,
                                              const std::map<std::string, std::string>& options,
                                              const std::string& atmosphere_label,
                                              const AtmosphereParameters& atmosphere, int width,
                                              int height, const std::vector<View>& views) {
    ReferenceFingerprint f;
    f.estimator_version = kReferenceEstimatorVersion;
    f.model = model;
    for (const auto& [name, value] : ResolvedModelOptions(model, options)) {
        f.model += ":" + name + "=" + value;
    }
    f.atmosphere = atmosphere_label;
    f.atmosphere_hash = HashText(AtmosphereToJson(atmosphere));
    f.width = width;
    f.height = height;
    for (const View& v : views) f.view_hashes[v.name] = HashText(ViewFingerprintText(v));
    return f;
}

std::string ReferenceFingerprintJson(const ReferenceFingerprint& fingerprint) {
    Json j = FingerprintFields(fingerprint);
    Json views = Json::object();
    for (const auto& [name, hash] : fingerprint.view_hashes) views[name] = hash;
    j["view_hashes"] = views;
    return j.dump(2) + "\n";
}

const ShippedView* ShippedReferences::Find(const std::string& view) const {
    for (const ShippedView& v : views) {
        if (v.view == view) return &v;
    }
    return nullptr;
}

namespace {

// DIR/provenance.json as JSON (atmos::Error when unreadable or not JSON).
Json ReadProvenanceJson(const std::string& directory) {
    const fs::path path = fs::path(directory) / "provenance.json";
    const std::string where = path.string();
    std::ifstream in(path);
    if (!in) Fail(where, ": cannot be read");
    try {
        return Json::parse(in);
    } catch (const std::exception& e) {
        const std::string what = e.what();
        const size_t end = what.find("] ");
        Fail(where, ": invalid JSON: ", end == std::string::npos ? what : what.substr(end + 2));
    }
}

// The validated contents of `j`, read from DIR/provenance.json.
ShippedReferences ShippedFromJson(const Json& j, const std::string& directory) {
    const std::string where = (fs::path(directory) / "provenance.json").string();
    if (j.is_object() && !j.contains("format")) {
        Fail(where,
             ": written by an older atmos (no format field); regenerate it with "
             "scripts/make_references.sh");
    }
    const std::string format = Field<std::string>(j, "format", where);
    if (format != kFormat) {
        Fail(where, ": format '", format, "' (this build reads '", kFormat,
             "'; regenerate it with scripts/make_references.sh)");
    }
    ShippedReferences s;
    s.directory = directory;
    const Json fp = j.contains("fingerprint") ? j["fingerprint"] : Json();
    const std::string fp_where = where + ": fingerprint";
    if (!fp.is_object()) Fail(fp_where, " is missing or not an object");
    ReferenceFingerprint& f = s.fingerprint;
    f.estimator_version = Field<int>(fp, "estimator_version", fp_where);
    f.model = Field<std::string>(fp, "model", fp_where);
    f.atmosphere = Field<std::string>(fp, "atmosphere", fp_where);
    f.atmosphere_hash = Field<std::string>(fp, "atmosphere_hash", fp_where);
    const std::string size = Field<std::string>(fp, "size", fp_where);
    char x = 0;
    std::istringstream size_in(size);
    if (!(size_in >> f.width >> x >> f.height) || x != 'x' || f.width <= 0 || f.height <= 0) {
        Fail(fp_where, ": size '", size, "' is not WIDTHxHEIGHT");
    }
    f.wavelengths = Field<std::string>(fp, "wavelengths", fp_where);
    f.quantity = Field<std::string>(fp, "quantity", fp_where);
    if (!j.contains("views") || !j["views"].is_array()) Fail(where, ": views is not a list");
    for (const Json& v : j["views"]) {
        ShippedView view;
        view.view = Field<std::string>(v, "view", where + ": a view");
        const std::string vw = where + ": view " + view.view;
        view.view_hash = Field<std::string>(v, "view_hash", vw);
        view.paths_per_pixel = Field<int64_t>(v, "paths_per_pixel", vw);
        view.noise = Field<double>(v, "noise", vw);
        if (v.contains("commit") && v["commit"].is_string()) view.commit = v["commit"];
        if (s.Find(view.view)) Fail(vw, ": given twice");
        if (view.paths_per_pixel <= 0 || !(view.noise >= 0.0 && view.noise < 1.0)) {
            Fail(vw, ": paths_per_pixel must be positive and noise in [0, 1)");
        }
        s.views.push_back(view);
    }
    return s;
}

}  // namespace

ShippedReferences ReadShippedReferences(const std::string& directory) {
    return ShippedFromJson(ReadProvenanceJson(directory), directory);
}

std::string ShippedMismatch(const ShippedReferences& shipped, const ReferenceFingerprint& run,
                            const std::string& view, double noise_target, int64_t spp) {
    std::vector<std::string> why = FingerprintMismatches(shipped.fingerprint, run);
    const ShippedView* v = shipped.Find(view);
    const auto hash = run.view_hashes.find(view);
    if (!v) {
        why.push_back("no shipped image of this view");
    } else if (hash == run.view_hashes.end() || hash->second != v->view_hash) {
        why.push_back("view differs");
    }
    if (why.empty()) {
        const bool quiet_enough = noise_target > 0.0 && v->noise <= noise_target;
        if (!quiet_enough && v->paths_per_pixel < spp) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "noise %.4g at %lld paths per pixel: above the target %.4g with fewer "
                          "paths than the run's %lld",
                          v->noise, static_cast<long long>(v->paths_per_pixel), noise_target,
                          static_cast<long long>(spp));
            why.push_back(buf);
        }
    }
    std::string text;
    for (const std::string& w : why) text += (text.empty() ? "" : "; ") + w;
    return text;
}

void LoadShippedImages(const ShippedReferences& shipped, const std::string& view, int width,
                       int height, Image* image, Image* variance) {
    const fs::path dir(shipped.directory);
    for (const auto& [file, out] :
         {std::make_pair(view + ".exr", image), std::make_pair(view + ".variance.exr", variance)}) {
        const std::string path = (dir / file).string();
        std::error_code ec;
        if (!fs::exists(path, ec)) Fail(path, " is missing");
        *out = ReadImage(path);
        if (out->width() != width || out->height() != height) {
            Fail(path, " is ", out->width(), "x", out->height(), ", not ", width, "x", height);
        }
        for (size_t i = 0; i < out->size(); ++i) {
            const float x = out->data()[i];
            if (!(std::isfinite(x) && x >= 0.0f)) {
                Fail(path, " holds a NaN, infinite or negative value");
            }
        }
    }
}

std::string LoadMatchingShippedView(const ShippedReferences& shipped,
                                    const ReferenceFingerprint& run, const std::string& view,
                                    double noise_target, int64_t spp, Image* image,
                                    Image* variance) {
    const std::string why = ShippedMismatch(shipped, run, view, noise_target, spp);
    if (!why.empty()) return why;
    try {
        LoadShippedImages(shipped, view, run.width, run.height, image, variance);
        return "";
    } catch (const std::exception& e) {
        *image = Image();
        *variance = Image();
        return e.what();
    }
}

void RecordShippedView(const std::string& directory, const ReferenceFingerprint& run,
                       const std::string& entry_json) {
    Json entry;
    try {
        entry = Json::parse(entry_json);
    } catch (const std::exception&) {
        Fail("reference-provenance --record: the entry is not JSON: ", entry_json);
    }
    const std::string where = "reference-provenance --record: the entry";
    const std::string view = Field<std::string>(entry, "view", where);
    const int64_t paths = Field<int64_t>(entry, "paths_per_pixel", where);
    const double noise = Field<double>(entry, "noise", where);
    if (paths <= 0 || !(noise >= 0.0 && noise < 1.0)) {
        Fail(where, ": paths_per_pixel must be positive and noise in [0, 1)");
    }
    const auto hash = run.view_hashes.find(view);
    if (hash == run.view_hashes.end()) Fail(where, ": view '", view, "' is not one of --views");
    entry["view_hash"] = hash->second;
    // Keep the other views' entries of a file with the same fingerprint.
    std::vector<Json> views;
    const fs::path path = fs::path(directory) / "provenance.json";
    std::error_code ec;
    if (fs::exists(path, ec)) {
        try {
            const Json file = ReadProvenanceJson(directory);
            const ShippedReferences old = ShippedFromJson(file, directory);
            if (FingerprintMismatches(old.fingerprint, run).empty()) {
                for (const Json& v : file.at("views")) views.push_back(v);
            }
        } catch (const Error&) {
            // An unreadable or older file describes nothing this run can keep.
        }
    }
    // The view's entry in its place, or last.
    bool replaced = false;
    for (Json& v : views) {
        if (v["view"] == view) {
            v = entry;
            replaced = true;
        }
    }
    if (!replaced) views.push_back(entry);
    fs::create_directories(directory);
    WriteFileAtomically(path.string(), ProvenanceText(FingerprintFields(run), views));
}

std::vector<ShippedViewCheck> CheckShippedViews(const std::string& directory,
                                                const ReferenceFingerprint& run,
                                                const std::vector<std::string>& views,
                                                double noise_target, int64_t spp) {
    std::unique_ptr<ShippedReferences> shipped;
    std::string unusable = "no provenance";
    if (std::filesystem::exists(std::filesystem::path(directory) / "provenance.json")) {
        try {
            shipped = std::make_unique<ShippedReferences>(ReadShippedReferences(directory));
        } catch (const Error& e) {
            std::fprintf(stderr, "atmos: warning: %s: every view renders\n", e.what());
            unusable = "no usable provenance";
        }
    }
    std::vector<ShippedViewCheck> checks;
    for (const std::string& view : views) {
        ShippedViewCheck c;
        c.view = view;
        Image image, variance;
        c.why = shipped ? LoadMatchingShippedView(*shipped, run, view, noise_target, spp, &image,
                                                  &variance)
                        : unusable;
        if (c.why.empty()) {
            const ShippedView& v = *shipped->Find(view);
            c.paths_per_pixel = v.paths_per_pixel;
            c.noise = v.noise;
        }
        checks.push_back(c);
    }
    return checks;
}

}  // namespace atmos
