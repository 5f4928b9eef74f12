// atmos: the on-disk render cache of `atmos compare`.
//
// An image is keyed by everything that determines it: the model's name and its
// resolved options (defaults included), the atmosphere (AtmosphereToJson), the
// view's name, the size and the quantity. The key text is hashed (FNV-1a, 64
// bit) into the file name; the key text itself is stored beside the image and
// compared on load, so a hash collision can never return a wrong image. The
// key does not cover the model's source code: after changing a model, delete
// the cache directory (or run compare with --no-cache).
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
};

// The canonical key text (one line per field).
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
    bool Load(const RenderKey& key, Image* image, double* render_seconds) const;
    void Store(const RenderKey& key, const Image& image, double render_seconds) const;
    // The EXR file of a key (whether or not it exists).
    std::string ImagePath(const RenderKey& key) const;

  private:
    std::string directory_;
};

}  // namespace atmos
