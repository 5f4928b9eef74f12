// atmos: machine description for measurements.
#include "harness/machine.h"

#include <ctime>
#include <fstream>
#include <string>

namespace atmos {

std::string CpuName() {
    std::ifstream f("/proc/cpuinfo");
    std::string line;
    while (std::getline(f, line)) {
        if (line.compare(0, 10, "model name") == 0) {
            const size_t colon = line.find(':');
            if (colon != std::string::npos) {
                const size_t start = line.find_first_not_of(' ', colon + 1);
                if (start != std::string::npos) return line.substr(start);
            }
        }
    }
    return "unknown";
}

std::string CompilerName() {
#if defined(__clang__)
    return std::string("Clang ") + __clang_version__;
#elif defined(__GNUC__)
    return std::string("GCC ") + __VERSION__;
#else
    return "unknown compiler";
#endif
}

std::string BuildType() {
    std::string s;
#ifdef NDEBUG
    s = "optimized (NDEBUG)";
#else
    s = "debug (assertions on)";
#endif
#if defined(__SANITIZE_ADDRESS__)
    s += ", AddressSanitizer";
#endif
    return s;
}

std::string UtcNow() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
    return buf;
}

}  // namespace atmos
