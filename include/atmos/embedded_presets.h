// atmos: the atmosphere presets embedded at build time from data/atmospheres/.
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

}  // namespace atmos::detail
