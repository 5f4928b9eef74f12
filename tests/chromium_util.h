// Finding Debian's Chromium on PATH for the tests that drive it headless
// (the report page, the viewer).
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

namespace atmos::test {

// The first chromium or chromium-browser executable on PATH; "" if none.
inline std::string FindChromium() {
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "/usr/bin:/bin");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        for (const char* name : {"chromium", "chromium-browser"}) {
            const std::filesystem::path p = std::filesystem::path(dir) / name;
            if (access(p.c_str(), X_OK) == 0) return p.string();
        }
    }
    return "";
}

}  // namespace atmos::test
