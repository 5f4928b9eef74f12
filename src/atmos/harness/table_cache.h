// atmos: the cache of precomputed tables (issue 33 item 4).
//
// A model that can bake (Model::CanBake) prepares through the cache: the key
// is the model's name, its table-shaping options (the option table's
// ShapesTables rows, defaults included), the atmosphere (AtmosphereToJson:
// every field at round-trip precision), the cache's format version and the
// identity of the code that computes the tables (a hash of the executable or
// shared library holding this function: a rebuilt atmos never reuses tables
// an older build made). The key text is hashed (FNV-1a, 64 bit) into the
// entry's directory name and stored in its manifest, where it is compared on
// load, so a hash collision cannot load the wrong tables.
//
// An entry is what `atmos bake` writes (Model::Bake: EXR tables + JSON) plus
// `manifest.json` (the key text, each file's size and FNV-1a checksum, the
// seconds the Prepare() took). It is written to a temporary directory and
// renamed into place, so a reader never sees a partial entry. A damaged entry
// (a file missing, resized or with another checksum, or refused by
// LoadBaked) is reported on stderr, removed and rebuilt. Entries are evicted
// least recently used first when the cache exceeds its size limit.
//
// Where: $XDG_CACHE_HOME/atmos/tables, else $HOME/.cache/atmos/tables.
// $ATMOS_NO_CACHE (any value but "" or "0") disables it (the test suite sets
// it), as does the commands' --no-cache; $ATMOS_CACHE_MAX_MB sets the limit
// (default 2048 MB).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/model.h"

namespace atmos {

constexpr int kTableCacheFormat = 1;
constexpr int64_t kTableCacheDefaultMaxBytes = int64_t{2048} << 20;

struct TableCacheSettings {
    std::string directory;  // the tables' root; empty: no cache
    int64_t max_bytes = kTableCacheDefaultMaxBytes;
};

// The user's cache (see above); `disabled` (--no-cache) gives no directory.
TableCacheSettings UserTableCache(bool disabled = false);

struct TablePrepareResult {
    bool from_cache = false;       // the tables were loaded from an entry
    bool stored = false;           // a new entry was written
    double prepare_seconds = 0.0;  // of the Prepare() that computed the tables
    std::string entry;             // the entry's directory ("" without a cache)
};

// The key text of `model` (with the options it was created with: `given`,
// resolved against its defaults) for `atmosphere`.
std::string TableCacheKeyText(const Model& model, const std::map<std::string, std::string>& given,
                              const AtmosphereParameters& atmosphere);

// model->Prepare(atmosphere), through the cache when it is enabled and the
// model can bake: an intact entry of the same key is loaded (LoadBaked),
// otherwise the model is prepared and a new entry stored. A cache that cannot
// be written (read-only, full disk) is skipped with a warning; the model is
// prepared in any case.
TablePrepareResult PrepareWithTableCache(Model* model,
                                         const std::map<std::string, std::string>& given,
                                         const AtmosphereParameters& atmosphere,
                                         const TableCacheSettings& settings);

// Whether the cache (enabled, for a model that can bake precomputed tables)
// has a completed entry of `model`'s key for `atmosphere` (not checked: a
// damaged one is rebuilt by PrepareWithTableCache).
bool TableCacheHasEntry(const Model& model, const std::map<std::string, std::string>& given,
                        const AtmosphereParameters& atmosphere, const TableCacheSettings& settings);

// The identity of the code: a 64-bit FNV-1a hash (hex) of the file this
// function was loaded from (the executable, or the Python module), computed
// once per process; "unknown" when it cannot be read.
std::string CodeIdentity();

}  // namespace atmos
