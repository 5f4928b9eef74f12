// atmos: the on-disk render cache of `atmos compare`.
//
// An image is keyed by everything that determines it: the model's name and its
// resolved options (defaults included), the atmosphere (AtmosphereToJson), the
// view's name, the size and the quantity. The key text is hashed (FNV-1a, 64
// bit) into the file name; the key text itself is stored beside the image and
// compared on load, so a hash collision can never return a wrong image. The
// key also holds the code's hash (CodeIdentity: the executable, or the Python
// module), so a rebuilt atmos (changed model code, new embedded neural weights
// or presets) never reuses an image an older build rendered; `--no-cache`
// skips the cache.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "atmos/image.h"
#include "atmos/model.h"

namespace atmos {

struct RenderKey {
    std::string model;
    std::map<std::string, std::string> options;  // resolved: every option, set or default
    std::string atmosphere_json;
    std::string view;
    int width = 0;
    int height = 0;
    Quantity quantity = Quantity::kRadiance;
    bool monte_carlo = false;  // a Monte Carlo model: `mc` determines the image too
    MonteCarloSettings mc;
};

// The canonical key text (one line per field, the code's identity included:
// CodeIdentity(), harness/table_cache.h, the executable or the Python module).
std::string RenderKeyText(const RenderKey& key);
std::uint64_t Fnv1a64(const std::string& text);
// The resolved options of a model (every option at its given value or default).
std::map<std::string, std::string> ResolvedModelOptions(
    const std::string& model, const std::map<std::string, std::string>& given);

class RenderCache {
  public:
    // An empty directory disables the cache (Load finds nothing, Store does nothing).
    explicit RenderCache(std::string directory);
    bool enabled() const { return !directory_.empty(); }
    // Loads the image and the seconds its render took; false when absent or stale.
    // A Monte Carlo render's report (reached noise, paths) travels with it,
    // and a noise-targeted render's per-pixel noise map (noise_map; an entry
    // whose measured noise has no valid map is a miss).
    // A Monte Carlo render's per-pixel variance, when stored with it, is
    // loaded into `variance` (left empty when absent).
    bool Load(const RenderKey& key, Image* image, double* render_seconds,
              MonteCarloReport* report = nullptr, Image* variance = nullptr) const;
    void Store(const RenderKey& key, const Image& image, double render_seconds,
               const MonteCarloReport* report = nullptr, const Image* variance = nullptr) const;
    // A model's precomputation (Prepare() seconds, bytes of its tables or -1),
    // keyed by the key's model, options, atmosphere and build (view and size
    // as given), so a run whose images all come from the cache still reports it.
    bool LoadPrepare(const RenderKey& key, double* seconds, int64_t* table_bytes) const;
    void StorePrepare(const RenderKey& key, double seconds, int64_t table_bytes) const;
    // The EXR file of a key (whether or not it exists).
    std::string ImagePath(const RenderKey& key) const;

  private:
    // Store's work; throws on a failure (Store warns and cleans up).
    void StoreEntry(const RenderKey& key, const Image& image, double render_seconds,
                    const MonteCarloReport* report, const Image* variance) const;

    std::string directory_;
};

}  // namespace atmos
