// atmos: lookup tables as files, for `atmos bake` (and --load).
//
// A table of W x H x D texels with C channels (1..4) is one float32 EXR image
// of W*D x H pixels: the D layers side by side, left to right (the layout
// Bruneton's demo uses for its 3D textures), channels R, G, B, A (the first C).
#pragma once

#include <string>

#include "base/texture.h"

namespace atmos {

void WriteTableExr(const Table& table, const std::string& path);
// Reads a table written by WriteTableExr; `depth` and `channels` come from the
// caller (the bake's JSON). Throws atmos::Error when the sizes disagree.
// When `path` (DIR/STEM.exr) does not exist, the table STEM is read from
// DIR/tables.f32 as the bake's JSON describes it under "raw" (a viewer's bake
// keeps only that blob: docs/engine.md, "The viewer").
Table ReadTableExr(const std::string& path, int depth, int channels);

}  // namespace atmos
