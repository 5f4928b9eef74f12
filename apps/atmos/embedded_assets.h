// atmos CLI: the engine assets embedded at build time (shaders/*.glsl,
// viewer/*.html, viewer/*.js; CMakeLists.txt): what `atmos bake` installs into
// DIR/shaders/ and `atmos viewer` writes beside the tables.
#pragma once

#include <string>

namespace atmos::cli {

struct EmbeddedAsset {
    const char* path;  // relative to the repository: "shaders/bruneton.glsl"
    const char* text;
};
// Terminated by {nullptr, nullptr}.
extern const EmbeddedAsset kEmbeddedAssets[];

// The text of asset `path`, or nullptr.
inline const char* FindAsset(const std::string& path) {
    for (const EmbeddedAsset* a = kEmbeddedAssets; a->path; ++a) {
        if (path == a->path) return a->text;
    }
    return nullptr;
}

}  // namespace atmos::cli
