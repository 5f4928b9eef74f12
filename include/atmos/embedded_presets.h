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

}  // namespace atmos::detail
