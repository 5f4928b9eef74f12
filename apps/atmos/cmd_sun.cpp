// atmos CLI: `atmos sun`: the sun's position for dates, times and places read as
// CSV `time,latitude,longitude` on stdin (issue 31 item 2; docs/sun.md).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "atmos/error.h"
#include "atmos/number.h"
#include "atmos/sun_position.h"
#include "cli_common.h"

namespace atmos::cli {

namespace sun_cmd {

constexpr char kHeader[] = "time,latitude,longitude";

std::string_view TrimField(std::string_view s) {
    const size_t b = s.find_first_not_of(" \t");
    if (b == std::string_view::npos) return {};
    return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

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
    while (!text.empty()) {
        const size_t eol = text.find('\n');
        std::string_view line = text.substr(0, eol);
        text = eol == std::string_view::npos ? std::string_view() : text.substr(eol + 1);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (line.find_first_not_of(" \t") == std::string_view::npos) continue;
        if (!header) {
            std::string compact;
            for (char c : line) {
                if (c != ' ' && c != '\t') compact += c;
            }
            if (compact != kHeader) {
                Fail("expected the header '", kHeader, "' on the first line, got '",
                     std::string(line), "'");
            }
            header = true;
            continue;
        }
        ++row_number;
        const std::string where = "row " + std::to_string(row_number);
        std::string_view fields[3];
        size_t count = 0;
        std::string_view rest = line;
        for (;;) {
            const size_t comma = rest.find(',');
            if (count < 3) fields[count] = TrimField(rest.substr(0, comma));
            ++count;
            if (comma == std::string_view::npos) break;
            rest = rest.substr(comma + 1);
        }
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

std::string ReadStdin() {
    std::string text;
    char buffer[1 << 16];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, stdin)) > 0) text.append(buffer, n);
    return text;
}

struct Flags {
    double height_m = 0.0;
    double pressure_mbar = 1010.0;
    double temperature_c = 10.0;
    double delta_t_s = std::nan("");
    CLI::Option* pressure = nullptr;
    CLI::Option* temperature = nullptr;
};

int Run(const Flags& f) {
    SunPositionSettings settings;
    settings.delta_t_s = f.delta_t_s;
    settings.refraction = f.pressure->count() > 0 || f.temperature->count() > 0;
    settings.pressure_mbar = f.pressure_mbar;
    settings.temperature_c = f.temperature_c;
    CheckSunSettings(settings, "sun");
    SunObserver check;
    check.height_m = f.height_m;
    CheckSunObserver(check, "--height");
    const std::vector<Row> rows = ParseRows(ReadStdin(), f.height_m);
    std::string out = std::string(kHeader) + ",elevation_deg,azimuth_deg\n";
    char buffer[96];
    for (const Row& r : rows) {
        const SunPosition p = ComputeSunPosition(r.julian_day, r.observer, settings);
        std::snprintf(buffer, sizeof buffer, ",%.6f,%.6f\n", p.elevation_deg, p.azimuth_deg);
        out += r.time + "," + r.latitude + "," + r.longitude + buffer;
    }
    std::fwrite(out.data(), 1, out.size(), stdout);
    return 0;
}

}  // namespace sun_cmd

Command AddSunCommand(CLI::App* root) {
    auto flags = std::make_shared<sun_cmd::Flags>();
    CLI::App* cmd = root->add_subcommand(
        "sun",
        "the sun's elevation and azimuth (NREL SPA) for CSV 'time,latitude,longitude' on stdin");
    cmd->footer(
        "Input: a header 'time,latitude,longitude', then one row per instant: an ISO-8601 time\n"
        "with Z or a UTC offset (2024-06-21T12:00:00Z, 2024-06-21T14:00:00+02:00), latitude\n"
        "-90..90 (north positive), longitude -180..180 (east positive), in degrees.\n"
        "Output: the same columns plus elevation_deg and azimuth_deg (clockwise from north):\n"
        "the geometric topocentric position, or the refracted one with --pressure/--temperature.");
    cmd->add_option("--height", flags->height_m,
                    "observer height above sea level, m (-1000..100000; parallax)")
        ->capture_default_str();
    flags->pressure = cmd->add_option("--pressure", flags->pressure_mbar,
                                      "add refraction (SPA eq. 42) at this pressure, mbar "
                                      "(0..2000; default 1010 when only --temperature is given)");
    flags->temperature = cmd->add_option("--temperature", flags->temperature_c,
                                         "add refraction at this air temperature, C (-100..100; "
                                         "default 10 when only --pressure is given)");
    cmd->add_option("--delta-t", flags->delta_t_s,
                    "TT - UT in seconds (default: Espenak & Meeus's polynomial for the date)");
    Command c;
    c.app = cmd;
    c.run = [flags] { return sun_cmd::Run(*flags); };
    return c;
}

}  // namespace atmos::cli
