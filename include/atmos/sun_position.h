// atmos: the sun's position for a date, time and place (issue 31 item 2).
//
// The topocentric solar elevation and azimuth of NREL's Solar Position
// Algorithm (I. Reda and A. Andreas, "Solar position algorithm for solar
// radiation applications", Solar Energy 76 (2004) 577-589; the equations are
// numbered as in its section 3). Geometric by default (no refraction); the
// optional refraction is the SPA's eq. 42. ISO-8601 times with a UTC offset,
// a ΔT default (Espenak & Meeus) and the `--sun time=...` spec parser are here
// too. docs/sun.md gives the method and the measured accuracy.
#pragma once

#include <limits>
#include <string>

namespace atmos {

// A time read from ISO-8601 text, as a Julian Day of Universal Time.
// Accepted: YYYY-MM-DDTHH:MM[:SS[.fff...]] followed by Z, +HH:MM, -HH:MM,
// +HHMM or +HH (the offset is required: a time without one is ambiguous).
// The calendar is the proleptic Gregorian one of ISO 8601; years 0001..6000
// (the SPA's range ends at 6000). A leap second (SS = 60) is accepted at
// 23:59. UTC is used as UT1 (|UT1 - UTC| < 0.9 s, at most 0.004 degrees of the
// Earth's rotation). Malformed text throws atmos::Error naming `field` and the
// part of the time that is wrong (month, day, hour, ... with its range).
double ParseIso8601(const std::string& text, const std::string& field = "time");

// The Julian Day of a UTC civil date and time (proleptic Gregorian calendar).
double JulianDayFromUtc(int year, int month, int day, int hour, int minute, double second);

// ΔT = TT - UT in seconds for a Julian Day (UT): the polynomial fits of
// F. Espenak and J. Meeus (NASA, "Polynomial expressions for Delta T",
// Five Millennium Canon of Solar Eclipses, NASA/TP-2006-214141), with the
// decimal year y = year + (month - 0.5) / 12. Within a few seconds of the
// measured values over 1950-2024; a predicted value after that (ΔT moves the
// sun by ~0.00004 degrees per second, so a few seconds do not matter here).
double DeltaTSeconds(double julian_day_ut);

struct SunObserver {
    double latitude_deg = 0.0;   // -90..90, north positive (geodetic)
    double longitude_deg = 0.0;  // -180..180, east positive
    double height_m = 0.0;       // above the ellipsoid (sea level), for parallax
};

struct SunPositionSettings {
    // ΔT in seconds; NaN: DeltaTSeconds() of the instant.
    double delta_t_s = std::numeric_limits<double>::quiet_NaN();
    // Atmospheric refraction (SPA eq. 42) at this pressure and temperature;
    // off by default (the geometric position).
    bool refraction = false;
    double pressure_mbar = 1010.0;  // SPA's default
    double temperature_c = 10.0;    // SPA's default
};

struct SunPosition {
    // Topocentric; apparent (refracted) when settings.refraction.
    double elevation_deg = 0.0;   // -90..90
    double azimuth_deg = 0.0;     // 0..360, clockwise from north (east = 90)
    double zenith_deg = 90.0;     // 90 - elevation
    double refraction_deg = 0.0;  // the correction added to the elevation
};

// Every intermediate quantity of the SPA (degrees unless noted), for tests
// against the paper's worked example (its Table A5.1) and for the curious.
struct SunPositionTrace {
    double jd = 0, jde = 0, jc = 0, jce = 0, jme = 0;
    double l_terms[6] = {0, 0, 0, 0, 0, 0};  // L0..L5 (eq. 9), units of 1e-8 rad
    double b_terms[2] = {0, 0};
    double r_terms[5] = {0, 0, 0, 0, 0};
    double l = 0, b = 0, r_au = 0;                         // heliocentric (eqs. 10-12)
    double theta = 0, beta = 0;                            // geocentric (eqs. 13-14)
    double x[5] = {0, 0, 0, 0, 0};                         // nutation arguments (eqs. 15-19)
    double delta_psi = 0, delta_epsilon = 0;               // nutation (eqs. 22-23)
    double epsilon0_arcsec = 0, epsilon = 0;               // obliquity (eqs. 24-25)
    double delta_tau = 0, lambda = 0;                      // aberration, apparent longitude (26-27)
    double nu0 = 0, nu = 0;                                // sidereal time at Greenwich (28-29)
    double alpha = 0, delta = 0;                           // geocentric RA, declination (30-31)
    double h = 0;                                          // local hour angle (32)
    double xi = 0, delta_alpha = 0;                        // parallax (33-37)
    double alpha_prime = 0, delta_prime = 0, h_prime = 0;  // topocentric (38-40)
    double e0 = 0, delta_e = 0, e = 0;                     // elevation (41-43)
    double gamma = 0, phi = 0;  // astronomers' and navigators' azimuth (45-46)
};

// The sun's topocentric position at a Julian Day (UT) for an observer. The
// observer is not validated here (ParseSunTimeSpec and the callers do that);
// values are finite for any finite input.
SunPosition ComputeSunPosition(double julian_day_ut, const SunObserver& observer,
                               const SunPositionSettings& settings = {},
                               SunPositionTrace* trace = nullptr);

// Range checks shared by every entry point: atmos::Error "WHERE: latitude X is
// outside -90..90" and so on. `where` prefixes the message ("--sun", "row 3").
void CheckSunObserver(const SunObserver& observer, const std::string& where);
void CheckSunSettings(const SunPositionSettings& settings, const std::string& where);

// A sun spec `time=ISO-8601,latitude=DEG,longitude=DEG[,height=M][,pressure=MBAR]
// [,temperature=C][,delta-t=S]` (the form `--sun time=...` takes). Giving
// pressure or temperature turns refraction on (the other then has SPA's
// default: 1010 mbar, 10 C). Unknown or repeated keys, missing keys, values
// that are not numbers or outside their ranges throw atmos::Error naming the
// key and its range.
struct SunTimeSpec {
    double julian_day_ut = 0.0;
    SunObserver observer;
    SunPositionSettings settings;
};
SunTimeSpec ParseSunTimeSpec(const std::string& spec);

// ParseSunTimeSpec + ComputeSunPosition.
SunPosition SunFromTimeSpec(const std::string& spec);

}  // namespace atmos
