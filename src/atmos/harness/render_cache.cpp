// atmos: the on-disk render cache (see render_cache.h).
#include "harness/render_cache.h"

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "atmos/error.h"
#include "base/fnv1a.h"
#include "harness/table_cache.h"
#include "io/output_path.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

// A noise-targeted render's per-pixel noise map (MonteCarloReport::noise_map)
// beside its image: STEM.noise-map.bin, width x height float32 in host byte
// order, its FNV-1a hash in the entry's JSON ("noise_map").
std::string NoiseMapPath(const std::string& exr) {
    return exr.substr(0, exr.size() - 4) + ".noise-map.bin";
}

// The map of an entry; false when absent, damaged (size, hash) or not a
// FLIP map (every value finite, in [0, 1]).
bool ReadNoiseMap(const std::string& path, const std::string& hash, size_t pixels,
                  std::vector<float>* map) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (bytes.size() != pixels * sizeof(float)) return false;
    if (Fnv1aHex(Fnv1a(bytes.data(), bytes.size())) != hash) return false;
    std::vector<float> values(pixels);
    std::memcpy(values.data(), bytes.data(), bytes.size());
    for (float v : values) {
        if (!(v >= 0.0f && v <= 1.0f)) return false;
    }
    *map = std::move(values);
    return true;
}

// An option whose value names a regular file (`neural:weights=FILE`,
// `hosek-wilkie:coefficients=FILE`): the file's content hash, so that a file
// rewritten in place (a refit into the same path) is a new key, not a stale
// image. Empty for any other value.
std::string OptionFileHash(const std::string& value) {
    std::error_code ec;
    if (value.empty() || !fs::is_regular_file(value, ec)) return "";
    std::ifstream in(value, std::ios::binary);
    if (!in) return "";
    return Fnv1aHex(Fnv1aStream(in));
}

}  // namespace

std::string RenderKeyText(const RenderKey& key) {
    std::ostringstream os;
    os << "atmos-render-cache 2\n";
    os << "build " << CodeIdentity() << "\n";
    os << "model " << key.model << "\n";
    for (const auto& [name, value] : key.options) {
        os << "option " << name << "=" << value;
        const std::string file_hash = OptionFileHash(value);
        if (!file_hash.empty()) os << " file-fnv1a=" << file_hash;
        os << "\n";
    }
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
    const std::string stem =
        key.model + "-" + key.view + "-" + Fnv1aHex(Fnv1a64(RenderKeyText(key)));
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
            report->noise_map.clear();
            // A noise-targeted render's measured noise comes with its map: an
            // entry without one (written before atmos stored it) or with a
            // damaged one is a miss, re-rendered, so that a cached run gives
            // the region noise an uncached one gives.
            if (key.monte_carlo && key.mc.noise_target > 0.0 && report->noise >= 0.0) {
                if (!j.contains("noise_map")) return false;
                const size_t pixels =
                    static_cast<size_t>(key.width) * static_cast<size_t>(key.height);
                if (!ReadNoiseMap(NoiseMapPath(exr), j.at("noise_map").get<std::string>(), pixels,
                                  &report->noise_map)) {
                    return false;
                }
            }
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

namespace {

// A cache that cannot be written (a full disk, a read-only directory) costs
// speed, not the run: one warning per process, and what the failed store
// wrote is removed (an entry is found by its JSON, written last).
void WarnCannotStore(const std::string& directory, const std::string& why) {
    static std::atomic<bool> warned{false};
    if (warned.exchange(true)) return;
    std::fprintf(stderr, "atmos: warning: render cache: cannot store in '%s' (%s); continuing\n",
                 directory.c_str(), why.c_str());
}

}  // namespace

void RenderCache::Store(const RenderKey& key, const Image& image, double render_seconds,
                        const MonteCarloReport* report, const Image* variance) const {
    if (!enabled()) return;
    const std::string exr = ImagePath(key);
    const std::string meta = exr.substr(0, exr.size() - 4) + ".json";
    try {
        StoreEntry(key, image, render_seconds, report, variance);
    } catch (const std::exception& e) {
        std::error_code ec;
        for (const std::string& file :
             {meta, exr, exr.substr(0, exr.size() - 4) + ".variance.exr", NoiseMapPath(exr)}) {
            fs::remove(file, ec);
        }
        WarnCannotStore(directory_, e.what());
    }
}

void RenderCache::StoreEntry(const RenderKey& key, const Image& image, double render_seconds,
                             const MonteCarloReport* report, const Image* variance) const {
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
    if (report && !report->noise_map.empty() &&
        report->noise_map.size() == static_cast<size_t>(image.width()) * image.height()) {
        std::string bytes(report->noise_map.size() * sizeof(float), '\0');
        std::memcpy(bytes.data(), report->noise_map.data(), bytes.size());
        WriteFileAtomically(NoiseMapPath(exr), bytes);
        j["noise_map"] = Fnv1aHex(Fnv1a(bytes.data(), bytes.size()));
    }
    WriteFileAtomically(meta, j.dump(1) + "\n");
}

namespace {

std::string PreparePath(const std::string& directory, const RenderKey& key) {
    RenderKey k = key;
    k.view = "(prepare)";
    return (fs::path(directory) /
            (key.model + "-prepare-" + Fnv1aHex(Fnv1a64(RenderKeyText(k))) + ".json"))
        .string();
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
    RenderKey k = key;
    k.view = "(prepare)";
    nlohmann::json j;
    j["key"] = RenderKeyText(k);
    j["prepare_seconds"] = seconds;
    j["table_bytes"] = table_bytes;
    const std::string path = PreparePath(directory_, key);
    try {
        fs::create_directories(directory_);
        WriteFileAtomically(path, j.dump(1) + "\n");
    } catch (const std::exception& e) {
        WarnCannotStore(directory_, e.what());
    }
}

}  // namespace atmos
