// atmos: what a measurement ran on (for bench CSVs and the compare report).
#pragma once

#include <string>

namespace atmos {

std::string CpuName();       // "model name" of /proc/cpuinfo, or "unknown"
std::string CompilerName();  // e.g. "GCC 12.2.0"
std::string BuildType();     // "Release" (NDEBUG) or "Debug", plus sanitizers if on
std::string UtcNow();        // "2026-01-01 12:00:00 UTC"

}  // namespace atmos
