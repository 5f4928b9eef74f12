// atmos: the small offline HTML page that shows a set of rendered views.
#pragma once

#include <string>
#include <vector>

namespace atmos {

struct GalleryEntry {
    std::string view;         // view name
    std::string description;  // what the view shows
    std::string image;        // PNG file name, relative to the page
    std::string exr;          // EXR file name, relative to the page (may be empty)
    double seconds = 0.0;     // render wall time
    float exposure = 1.0f;
};

// Writes `path` (an HTML file that only references the images beside it).
void WriteGalleryHtml(const std::string& path, const std::string& title,
                      const std::string& subtitle, const std::vector<GalleryEntry>& entries);

}  // namespace atmos
