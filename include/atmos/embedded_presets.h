// atmos: the data files embedded at build time (CMakeLists.txt, atmos_embed_data):
// the atmosphere presets of data/atmospheres/, the spectra of data/spectra/ and
// the models' shipped data (data/neural/, data/hosek-wilkie-2012/).
#pragma once

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

}  // namespace atmos::detail
