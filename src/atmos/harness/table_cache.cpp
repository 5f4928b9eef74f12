// atmos: the cache of precomputed tables (see table_cache.h).
#include "harness/table_cache.h"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <system_error>
#include <vector>

#include "atmos/error.h"
#include "base/fnv1a.h"
#include "io/output_path.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

constexpr const char* kManifest = "manifest.json";

uint64_t HashText(const std::string& text) {
    std::istringstream in(text);
    return Fnv1aStream(in, nullptr);
}

// Size and checksum of a file; false when it cannot be read.
bool HashFile(const fs::path& path, int64_t* bytes, std::string* checksum) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    *checksum = Fnv1aHex(Fnv1aStream(in, bytes));
    return true;
}

void Warn(const std::string& text) { std::fprintf(stderr, "atmos: warning: %s\n", text.c_str()); }

int64_t DirectoryBytes(const fs::path& dir) {
    int64_t total = 0;
    std::error_code ec;
    for (const auto& f : fs::recursive_directory_iterator(dir, ec)) {
        std::error_code e2;
        if (f.is_regular_file(e2)) total += static_cast<int64_t>(f.file_size(e2));
    }
    return total;
}

// Why the entry at `dir` cannot be used for `key_text` ("" when it is intact).
std::string CheckEntry(const fs::path& dir, const std::string& key_text, double* seconds) {
    std::ifstream in(dir / kManifest);
    if (!in) return "its manifest cannot be read";
    nlohmann::json manifest;
    try {
        in >> manifest;
        if (manifest.at("key").get<std::string>() != key_text) return "its key differs";
        *seconds = manifest.at("prepare_seconds").get<double>();
        for (const auto& f : manifest.at("files")) {
            const std::string name = f.at("name").get<std::string>();
            int64_t bytes = 0;
            std::string checksum;
            if (!HashFile(dir / name, &bytes, &checksum)) return name + " is missing";
            if (bytes != f.at("bytes").get<int64_t>()) return name + " has another size";
            if (checksum != f.at("fnv1a64").get<std::string>()) return name + " fails its checksum";
        }
    } catch (const std::exception&) {
        return "its manifest is malformed";
    }
    return "";
}

// Removes entries, least recently used first (the manifest's time, touched
// on every hit), until the cache holds at most max_bytes; never `keep`.
// Leftover temporary directories older than an hour go too.
void Evict(const fs::path& root, int64_t max_bytes, const fs::path& keep) {
    struct Entry {
        fs::path dir;
        fs::file_time_type used;
        int64_t bytes;
    };
    std::vector<Entry> entries;
    int64_t total = 0;
    std::error_code ec;
    const auto now = fs::file_time_type::clock::now();
    for (const auto& e : fs::directory_iterator(root, ec)) {
        std::error_code e2;
        if (!e.is_directory(e2)) continue;
        const std::string name = e.path().filename().string();
        if (name.rfind(".tmp-", 0) == 0) {
            const auto t = fs::last_write_time(e.path(), e2);
            if (!e2 && now - t > std::chrono::hours(1)) fs::remove_all(e.path(), e2);
            continue;
        }
        auto used = fs::last_write_time(e.path() / kManifest, e2);
        if (e2) used = fs::file_time_type::min();  // no manifest: first to go
        const int64_t bytes = DirectoryBytes(e.path());
        entries.push_back({e.path(), used, bytes});
        total += bytes;
    }
    std::sort(entries.begin(), entries.end(),
              [](const Entry& a, const Entry& b) { return a.used < b.used; });
    for (const Entry& e : entries) {
        if (total <= max_bytes) break;
        if (e.dir == keep) continue;
        std::error_code e2;
        fs::remove_all(e.dir, e2);
        if (!e2) total -= e.bytes;
    }
}

}  // namespace

std::string CodeIdentity() {
    static const std::string identity = [] {
        std::string path = "/proc/self/exe";
        Dl_info info{};
        if (dladdr(reinterpret_cast<void*>(&CodeIdentity), &info) != 0 && info.dli_fname &&
            info.dli_fname[0] != '\0') {
            std::error_code ec;
            // The main executable may be named as it was typed (argv[0]).
            if (fs::is_regular_file(info.dli_fname, ec) &&
                !fs::equivalent(info.dli_fname, "/proc/self/exe", ec)) {
                path = info.dli_fname;
            }
        }
        std::ifstream in(path, std::ios::binary);
        if (!in) return std::string("unknown");
        return Fnv1aHex(Fnv1aStream(in, nullptr));
    }();
    return identity;
}

TableCacheSettings UserTableCache(bool disabled) {
    TableCacheSettings s;
    const char* no_cache = std::getenv("ATMOS_NO_CACHE");
    if (disabled || (no_cache && *no_cache && std::string(no_cache) != "0")) return s;
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    if (xdg && *xdg == '/') {
        s.directory = (fs::path(xdg) / "atmos" / "tables").string();
    } else if (home && *home) {
        s.directory = (fs::path(home) / ".cache" / "atmos" / "tables").string();
    }
    if (const char* mb = std::getenv("ATMOS_CACHE_MAX_MB")) {
        char* end = nullptr;
        const double v = std::strtod(mb, &end);
        if (end == mb || *end != '\0' || !(v >= 0.0) || v > 1e9) {
            Fail("ATMOS_CACHE_MAX_MB='", mb, "': expected megabytes in [0, 1e9]");
        }
        s.max_bytes = static_cast<int64_t>(v * 1048576.0);
    }
    return s;
}

std::string TableCacheKeyText(const Model& model, const std::map<std::string, std::string>& given,
                              const AtmosphereParameters& atmosphere) {
    const ModelInfo& info = model.Info();
    std::ostringstream os;
    os << "atmos-table-cache " << kTableCacheFormat << "\n";
    os << "code " << CodeIdentity() << "\n";
    os << "model " << info.name << "\n";
    const auto resolved = ResolveModelOptions(info.name, given);
    for (const ModelOptionSpec& spec : info.options) {
        if (!spec.shapes_tables) continue;
        for (const auto& [name, value] : resolved) {
            if (name == spec.name) os << "option " << name << "=" << value << "\n";
        }
    }
    os << "atmosphere " << AtmosphereToJson(atmosphere) << "\n";
    return os.str();
}

bool TableCacheHasEntry(const Model& model, const std::map<std::string, std::string>& given,
                        const AtmosphereParameters& atmosphere,
                        const TableCacheSettings& settings) {
    if (settings.directory.empty() || !model.CanBake() || !model.Info().capabilities.precomputed) {
        return false;
    }
    const std::string key = TableCacheKeyText(model, given, atmosphere);
    const fs::path entry =
        fs::path(settings.directory) / (model.Info().name + "-" + Fnv1aHex(HashText(key)));
    std::error_code ec;
    return fs::exists(entry / kManifest, ec);
}

TablePrepareResult PrepareWithTableCache(Model* model,
                                         const std::map<std::string, std::string>& given,
                                         const AtmosphereParameters& atmosphere,
                                         const TableCacheSettings& settings) {
    TablePrepareResult result;
    const auto prepare = [&] {
        const auto start = std::chrono::steady_clock::now();
        model->Prepare(atmosphere);
        result.prepare_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    // Only tables worth caching: a model that bakes constants alone
    // (hosek-wilkie's shader) prepares in microseconds.
    if (settings.directory.empty() || !model->CanBake() ||
        !model->Info().capabilities.precomputed) {
        prepare();
        return result;
    }
    const std::string key = TableCacheKeyText(*model, given, atmosphere);
    const fs::path root(settings.directory);
    const fs::path entry = root / (model->Info().name + "-" + Fnv1aHex(HashText(key)));
    result.entry = entry.string();
    std::error_code ec;
    if (fs::exists(entry / kManifest, ec)) {
        double seconds = 0.0;
        std::string why = CheckEntry(entry, key, &seconds);
        if (why.empty()) {
            try {
                model->LoadBaked(entry.string(), atmosphere);
            } catch (const std::exception& e) {
                why = std::string("its tables were refused (") + e.what() + ")";
            }
        }
        if (why.empty()) {
            fs::last_write_time(entry / kManifest, fs::file_time_type::clock::now(), ec);
            result.from_cache = true;
            result.prepare_seconds = seconds;
            return result;
        }
        Warn("table cache: the entry " + entry.string() + " is damaged (" + why +
             "); rebuilding it");
        fs::remove_all(entry, ec);
    } else if (fs::exists(entry, ec)) {
        fs::remove_all(entry, ec);  // no manifest: never completed
    }
    prepare();
    // Store: bake into a temporary directory, add the manifest, rename into place.
    std::mt19937_64 rng(std::random_device{}());
    const fs::path tmp = root / (".tmp-" + Fnv1aHex(rng()) + "-" + std::to_string(getpid()));
    try {
        fs::create_directories(tmp);
        model->Bake(tmp.string());
        nlohmann::json files = nlohmann::json::array();
        std::vector<std::string> names;
        for (const auto& f : fs::recursive_directory_iterator(tmp)) {
            if (f.is_regular_file()) names.push_back(fs::relative(f.path(), tmp).string());
        }
        std::sort(names.begin(), names.end());
        for (const std::string& name : names) {
            int64_t bytes = 0;
            std::string checksum;
            if (!HashFile(tmp / name, &bytes, &checksum))
                Fail("cannot read ", (tmp / name).string());
            files.push_back({{"name", name}, {"bytes", bytes}, {"fnv1a64", checksum}});
        }
        nlohmann::json manifest;
        manifest["key"] = key;
        manifest["prepare_seconds"] = result.prepare_seconds;
        manifest["files"] = files;
        // Written last and checked through its close (a full disk would
        // otherwise leave a truncated manifest in a stored entry).
        WriteFileAtomically((tmp / kManifest).string(), manifest.dump(1) + "\n");
        fs::rename(tmp, entry, ec);
        if (ec) {
            fs::remove_all(tmp, ec);  // another process stored it first
        } else {
            result.stored = true;
        }
        Evict(root, settings.max_bytes, entry);
    } catch (const fs::filesystem_error& e) {
        fs::remove_all(tmp, ec);
        Warn("table cache: cannot store the tables in " + root.string() + " ('" +
             e.path1().string() + "': " + e.code().message() + ")");
    } catch (const std::exception& e) {
        fs::remove_all(tmp, ec);
        Warn(std::string("table cache: cannot store the tables in ") + root.string() + " (" +
             e.what() + ")");
    }
    return result;
}

}  // namespace atmos
