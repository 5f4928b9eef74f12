// atmos: the on-disk render cache (see render_cache.h).
#include "harness/render_cache.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "atmos/error.h"
#include "base/fnv1a.h"
#include "io/output_path.h"

namespace fs = std::filesystem;

namespace atmos {

std::string BuildIdentity() {
    static const std::string identity = [] {
        std::ifstream exe("/proc/self/exe", std::ios::binary);
        if (!exe) return std::string("unknown");
        const std::uint64_t h = Fnv1aStream(exe);
        char text[17];
        std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(h));
        return std::string(text);
    }();
    return identity;
}

std::string RenderKeyText(const RenderKey& key) {
    std::ostringstream os;
    os << "atmos-render-cache 2\n";
    os << "build " << BuildIdentity() << "\n";
    os << "model " << key.model << "\n";
    for (const auto& [name, value] : key.options) os << "option " << name << "=" << value << "\n";
    if (key.monte_carlo) {
        os << "monte-carlo spp=" << key.mc.spp << " seed=" << key.mc.seed
           << " pass-spp=" << key.mc.pass_spp;
        if (key.mc.noise_target > 0.0) os << " noise-target=" << key.mc.noise_target;
        os << "\n";
    }
    os << "view " << key.view << "\n";
    os << "size " << key.width << "x" << key.height << "\n";
    os << "quantity " << QuantityName(key.quantity) << "\n";
    os << "atmosphere " << key.atmosphere_json << "\n";
    return os.str();
}

std::uint64_t Fnv1a64(const std::string& text) { return Fnv1a(text.data(), text.size()); }

std::map<std::string, std::string> ResolvedModelOptions(
    const std::string& model, const std::map<std::string, std::string>& given) {
    std::map<std::string, std::string> resolved;
    for (const auto& [name, value] : ResolveModelOptions(model, given)) resolved[name] = value;
    return resolved;
}

RenderCache::RenderCache(std::string directory) : directory_(std::move(directory)) {}

std::string RenderCache::ImagePath(const RenderKey& key) const {
    char hash[17];
    std::snprintf(hash, sizeof hash, "%016llx",
                  static_cast<unsigned long long>(Fnv1a64(RenderKeyText(key))));
    const std::string stem = key.model + "-" + key.view + "-" + hash;
    return (fs::path(directory_) / (stem + ".exr")).string();
}

bool RenderCache::Load(const RenderKey& key, Image* image, double* render_seconds,
                       MonteCarloReport* report, Image* variance) const {
    if (!enabled()) return false;
    const std::string exr = ImagePath(key);
    const std::string meta = exr.substr(0, exr.size() - 4) + ".json";
    std::error_code ec;
    if (!fs::exists(exr, ec) || !fs::exists(meta, ec)) return false;
    try {
        std::ifstream f(meta);
        const nlohmann::json j = nlohmann::json::parse(f);
        if (j.at("key").get<std::string>() != RenderKeyText(key)) return false;
        Image loaded = ReadImage(exr);
        if (loaded.width() != key.width || loaded.height() != key.height) return false;
        *image = std::move(loaded);
        *render_seconds = j.at("render_seconds").get<double>();
        if (report) {
            report->samples = j.value("samples", static_cast<int64_t>(0));
            report->noise = j.value("noise", -1.0);
        }
        if (variance) {
            *variance = Image();
            const std::string file = exr.substr(0, exr.size() - 4) + ".variance.exr";
            if (j.value("variance", false) && fs::exists(file, ec)) {
                Image v = ReadImage(file);
                if (v.width() == key.width && v.height() == key.height) *variance = std::move(v);
            }
        }
        return true;
    } catch (const std::exception&) {
        return false;  // a damaged entry is re-rendered (and overwritten)
    }
}

void RenderCache::Store(const RenderKey& key, const Image& image, double render_seconds,
                        const MonteCarloReport* report, const Image* variance) const {
    if (!enabled()) return;
    fs::create_directories(directory_);
    const std::string exr = ImagePath(key);
    const std::string meta = exr.substr(0, exr.size() - 4) + ".json";
    WriteImage(image, exr);
    nlohmann::json j;
    j["key"] = RenderKeyText(key);
    j["render_seconds"] = render_seconds;
    if (report) {
        j["samples"] = report->samples;
        j["noise"] = report->noise;
    }
    if (variance && variance->width() == image.width() && variance->height() == image.height()) {
        WriteImage(*variance, exr.substr(0, exr.size() - 4) + ".variance.exr");
        j["variance"] = true;
    }
    WriteFileAtomically(meta, j.dump(1) + "\n");
}

namespace {

std::string PreparePath(const std::string& directory, const RenderKey& key) {
    RenderKey k = key;
    k.view = "(prepare)";
    char hash[17];
    std::snprintf(hash, sizeof hash, "%016llx",
                  static_cast<unsigned long long>(Fnv1a64(RenderKeyText(k))));
    return (fs::path(directory) / (key.model + "-prepare-" + hash + ".json")).string();
}

}  // namespace

bool RenderCache::LoadPrepare(const RenderKey& key, double* seconds, int64_t* table_bytes) const {
    if (!enabled()) return false;
    RenderKey k = key;
    k.view = "(prepare)";
    try {
        std::ifstream f(PreparePath(directory_, key));
        if (!f) return false;
        const nlohmann::json j = nlohmann::json::parse(f);
        if (j.at("key").get<std::string>() != RenderKeyText(k)) return false;
        *seconds = j.at("prepare_seconds").get<double>();
        *table_bytes = j.at("table_bytes").get<int64_t>();
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

void RenderCache::StorePrepare(const RenderKey& key, double seconds, int64_t table_bytes) const {
    if (!enabled()) return;
    fs::create_directories(directory_);
    RenderKey k = key;
    k.view = "(prepare)";
    nlohmann::json j;
    j["key"] = RenderKeyText(k);
    j["prepare_seconds"] = seconds;
    j["table_bytes"] = table_bytes;
    const std::string path = PreparePath(directory_, key);
    WriteFileAtomically(path, j.dump(1) + "\n");
}

}  // namespace atmos
