// atmos tests: a compare study small enough for a unit test.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "studies/compare.h"

namespace atmos {

// `models` against naive:steps=8 at `views`, 8x4 pixels, into `out`: no
// render cache, no .npy, no progress.
inline CompareRequest TinyCompareRequest(const std::vector<std::string>& models,
                                         const std::vector<std::string>& views,
                                         const std::filesystem::path& out) {
    CompareRequest q;
    q.models = models;
    q.views = views;
    q.width = 8;
    q.height = 4;
    q.reference = "naive:steps=8";
    q.output_dir = out.string();
    q.no_cache = true;
    q.write_npy = false;
    q.show_progress = false;
    return q;
}

}  // namespace atmos
