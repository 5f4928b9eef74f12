// atmos io: the sun's position for a CSV of dates, times and places, the text
// `atmos sun` reads and writes (docs/sun.md).
#pragma once

#include <string>
#include <string_view>

#include "atmos/sun_position.h"

namespace atmos {

// `input`: a header 'time,latitude,longitude', then one row per instant (ISO-8601
// time with Z or a UTC offset, latitude -90..90, longitude -180..180, degrees).
// Returns the same columns plus elevation_deg,azimuth_deg (6 decimals). Every row
// is checked before any is computed: one atmos::Error names the row (data rows
// count from 1 after the header), the column and its range.
std::string SunPositionsCsv(std::string_view input, double height_m,
                            const SunPositionSettings& settings);

}  // namespace atmos
