// atmos: the data files embedded at build time (CMakeLists.txt, atmos_embed_data):
// the atmosphere presets of data/atmospheres/, the spectra of data/spectra/ and
// the models' shipped data (data/neural/, data/hosek-wilkie-2012/).
#pragma once

#include <algorithm>
#include <string>
#include <vector>

namespace atmos::detail {

struct EmbeddedPreset {
    const char* name;  // file name without ".json"
    const char* json;  // the file's text
};
// Terminated by {nullptr, nullptr}; kEmbeddedPresetCount excludes the terminator.
extern const EmbeddedPreset kEmbeddedPresets[];
extern const int kEmbeddedPresetCount;
// The spectral tables of data/spectra/*.csv (name without ".csv", the CSV text).
extern const EmbeddedPreset kEmbeddedSpectra[];
extern const int kEmbeddedSpectrumCount;
// `neural`'s shipped weights (data/neural/*.json) and Hosek & Wilkie's published
// data (data/hosek-wilkie-2012/*.json), each terminated by {nullptr, nullptr}.
extern const EmbeddedPreset kEmbeddedNeuralWeights[];
extern const EmbeddedPreset kEmbeddedHosekWilkie[];

// The names of the first `count` entries of `files`, sorted.
inline std::vector<std::string> SortedNames(const EmbeddedPreset* files, int count) {
    std::vector<std::string> names;
    for (int i = 0; i < count; ++i) names.emplace_back(files[i].name);
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace atmos::detail
