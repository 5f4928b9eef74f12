#include "harness/gallery.h"

#include "harness/html.h"

#include <cstdio>
#include <fstream>

#include "atmos/error.h"
#include "io/output_path.h"

namespace atmos {

void WriteGalleryHtml(const std::string& path, const std::string& title,
                      const std::string& subtitle, const std::vector<GalleryEntry>& entries) {
    TextOutput f(path);
    f << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>"
      << HtmlEscape(title) << "</title>\n<style>\n"
      << "body{font-family:sans-serif;background:#111;color:#ddd;margin:2em}\n"
      << "h1{font-weight:normal}.grid{display:grid;grid-template-columns:repeat(auto-fill,"
         "minmax(420px,1fr));gap:1.2em}\n"
      << "figure{margin:0}img{width:100%;display:block;background:#000}\n"
      << "figcaption{font-size:.85em;margin-top:.3em;color:#aaa}b{color:#fff}a{color:#8cf}\n"
      << "</style></head><body>\n<h1>" << HtmlEscape(title) << "</h1>\n<p>" << HtmlEscape(subtitle)
      << "</p>\n<div class=\"grid\">\n";
    for (const GalleryEntry& e : entries) {
        char timing[64];
        std::snprintf(timing, sizeof timing, "%.3f s", e.seconds);
        char exposure[32];
        std::snprintf(exposure, sizeof exposure, "%g", static_cast<double>(e.exposure));
        f << "<figure><img src=\"" << HtmlEscape(e.image) << "\" alt=\"" << HtmlEscape(e.view)
          << "\"><figcaption><b>" << HtmlEscape(e.view) << "</b> &mdash; "
          << HtmlEscape(e.description) << "<br>exposure " << exposure << ", render " << timing;
        if (!e.exr.empty()) f << ", <a href=\"" << HtmlEscape(e.exr) << "\">EXR</a>";
        f << "</figcaption></figure>\n";
    }
    f << "</div>\n</body></html>\n";
    f.Commit();
}

}  // namespace atmos
