// atmos io: the sun's position for a CSV of dates, times and places (`atmos sun`;
// sun_csv.h).
#include "io/sun_csv.h"

#include <cstdio>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/number.h"
#include "io/csv_fields.h"

namespace atmos {

namespace {

constexpr char kHeader[] = "time,latitude,longitude";

struct Row {
    std::string time, latitude, longitude;  // as given (trimmed), echoed
    double julian_day = 0.0;
    SunObserver observer;
};

// All rows, checked before anything is written: one error names the row (data
// rows count from 1 after the header), the column and its range.
std::vector<Row> ParseRows(std::string_view text, double height_m) {
    std::vector<Row> rows;
    bool header = false;
    int row_number = 0;
    int lines = 0;
    std::string_view line;
    while (NextCsvLine(&text, &line, &lines)) {
        if (!header) {
            if (!IsCsvHeader(line, kHeader)) {
                Fail("expected the header '", kHeader, "' on the first line, got '",
                     std::string(line), "'");
            }
            header = true;
            continue;
        }
        ++row_number;
        const std::string where = "row " + std::to_string(row_number);
        std::string_view fields[3];
        const size_t count = SplitCsvFields(line, fields, 3, /*trailing_comma_ends=*/false);
        if (count != 3) {
            Fail(where, ": expected 3 comma-separated fields (", kHeader, "), got ", count);
        }
        Row r;
        r.time = std::string(fields[0]);
        r.latitude = std::string(fields[1]);
        r.longitude = std::string(fields[2]);
        r.julian_day = ParseIso8601(r.time, where + ": time");
        double* values[2] = {&r.observer.latitude_deg, &r.observer.longitude_deg};
        const char* names[2] = {"latitude", "longitude"};
        for (int i = 0; i < 2; ++i) {
            const NumberError e = ParseNumber(fields[i + 1], values[i]);
            if (e != NumberError::kNone) {
                Fail(where, ": ", names[i], " '", std::string(fields[i + 1]), "' ",
                     NumberErrorText(e));
            }
        }
        r.observer.height_m = height_m;
        CheckSunObserver(r.observer, where);
        rows.push_back(std::move(r));
    }
    if (!header) Fail("no input: expected the header '", kHeader, "' on stdin");
    return rows;
}

}  // namespace

std::string SunPositionsCsv(std::string_view input, double height_m,
                            const SunPositionSettings& settings) {
    CheckSunSettings(settings, "sun");
    SunObserver check;
    check.height_m = height_m;
    CheckSunObserver(check, "--height");
    const std::vector<Row> rows = ParseRows(input, height_m);
    std::string out = std::string(kHeader) + ",elevation_deg,azimuth_deg\n";
    char buffer[96];
    for (const Row& r : rows) {
        const SunPosition p = ComputeSunPosition(r.julian_day, r.observer, settings);
        std::snprintf(buffer, sizeof buffer, ",%.6f,%.6f\n", p.elevation_deg, p.azimuth_deg);
        out += r.time + "," + r.latitude + "," + r.longitude + buffer;
    }
    return out;
}

}  // namespace atmos
