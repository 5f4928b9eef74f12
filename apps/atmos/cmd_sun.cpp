// atmos CLI: `atmos sun`: the sun's position for dates, times and places read as
// CSV `time,latitude,longitude` on stdin (issue 31 item 2; docs/sun.md).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "atmos/error.h"
#include "atmos/sun_position.h"
#include "cli_common.h"
#include "io/sun_csv.h"

namespace atmos::cli {

namespace sun_cmd {

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
    const std::string out = SunPositionsCsv(ReadStdin(), f.height_m, settings);
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
