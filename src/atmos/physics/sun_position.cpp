// atmos: the sun's position for a date, time and place (include/atmos/sun_position.h).
//
// NREL's Solar Position Algorithm, I. Reda and A. Andreas, "Solar position
// algorithm for solar radiation applications", Solar Energy 76 (2004)
// 577-589, section 3 (equation numbers below are the paper's). Written from
// the equations; the periodic terms (published data) are in
// sun_position_terms.h.
#include "atmos/sun_position.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>
#include <vector>

#include "atmos/error.h"
#include "atmos/number.h"
#include "physics/sun_position_terms.h"

namespace atmos {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRad = kPi / 180.0;

double Deg(double radians) { return radians / kRad; }
double SinD(double degrees) { return std::sin(degrees * kRad); }
double CosD(double degrees) { return std::cos(degrees * kRad); }

// An angle reduced to [0, 360).
double Wrap360(double degrees) {
    double w = std::fmod(degrees, 360.0);
    if (w < 0.0) w += 360.0;
    if (w >= 360.0) w = 0.0;  // -1e-17 + 360 rounds to 360
    return w;
}

// Eq. 9: sum of A cos(B + C JME) over a table's rows.
template <size_t N>
double SumTerms(const spa::Term (&terms)[N], double jme) {
    double sum = 0.0;
    for (const spa::Term& t : terms) sum += t.a * std::cos(t.b + t.c * jme);
    return sum;
}

// out[i] = SumTerms of the i-th table, for the tables of one series (L0..L5,
// B0..B1 or R0..R4).
template <size_t... N>
void SumEachTable(double jme, double* out, const spa::Term (&... tables)[N]) {
    int i = 0;
    ((out[i++] = SumTerms(tables, jme)), ...);
}

// Eqs. 10-11: (X0 + X1 JME + X2 JME^2 + ...) / 1e8, the polynomial in JME.
double Series(const double* x, int n, double jme) {
    double v = 0.0;
    for (int i = n - 1; i >= 0; --i) v = v * jme + x[i];
    return v / 1e8;
}

// --- ISO 8601 ---------------------------------------------------------------

bool IsLeapYear(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

int DaysInMonth(int y, int m) {
    static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return m == 2 && IsLeapYear(y) ? 29 : kDays[m - 1];
}

// Days from 1970-01-01 to a proleptic Gregorian date (y, m, d): the day count
// of the March-based year (the leap day last), by 400-year eras.
int64_t DaysFromCivil(int64_t y, int m, int d) {
    y -= m <= 2 ? 1 : 0;
    const int64_t era = (y >= 0 ? y : y - 399) / 400;
    const int64_t yoe = y - era * 400;                          // [0, 399]
    const int64_t mp = (m + 9) % 12;                            // March = 0
    const int64_t doy = (153 * mp + 2) / 5 + d - 1;             // [0, 365]
    const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;  // [0, 146096]
    return era * 146097 + doe - 719468;
}

class TimeParser {
  public:
    TimeParser(const std::string& text, const std::string& field) : text_(text), field_(field) {}

    [[noreturn]] void Bad(const std::string& what) const {
        Fail(field_, ": '", text_,
             "' is not an ISO-8601 time YYYY-MM-DDTHH:MM[:SS[.fff]] with Z or ",
             "a UTC offset (+HH:MM / -HH:MM): ", what);
    }

    // Exactly `n` decimal digits as the named part.
    int Digits(int n, const char* part) {
        int v = 0;
        for (int i = 0; i < n; ++i) {
            if (pos_ >= text_.size() || text_[pos_] < '0' || text_[pos_] > '9') {
                Bad(std::string("the ") + part + " needs " + std::to_string(n) + " digits");
            }
            v = v * 10 + (text_[pos_++] - '0');
        }
        return v;
    }
    void Expect(char c, const char* after) {
        if (pos_ >= text_.size() || text_[pos_] != c) {
            Bad(std::string("expected '") + c + "' after the " + after);
        }
        ++pos_;
    }
    bool Peek(char c) const { return pos_ < text_.size() && text_[pos_] == c; }
    bool AtEnd() const { return pos_ >= text_.size(); }
    char Next() { return text_[pos_++]; }
    size_t pos_ = 0;
    const std::string& text_;
    const std::string& field_;
};

void Range(const TimeParser& p, const char* part, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%g", v);
        p.Bad(std::string("the ") + part + " " + buf + " is outside " + std::to_string(int(lo)) +
              ".." + std::to_string(int(hi)));
    }
}

// --- the spec parser ----------------------------------------------------------

std::string FormatRange(double lo, double hi) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%g..%g", lo, hi);
    return buf;
}

void CheckValue(const std::string& where, const char* key, double v, double lo, double hi,
                const char* unit) {
    if (!(v >= lo && v <= hi)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", v);
        Fail(where, ": ", key, " ", buf, " is outside ", FormatRange(lo, hi), unit);
    }
}

}  // namespace

double JulianDayFromUtc(int year, int month, int day, int hour, int minute, double second) {
    const int64_t days = DaysFromCivil(year, month, day);
    // 2440587.5 is the Julian Day of 1970-01-01T00:00Z.
    return 2440587.5 + static_cast<double>(days) +
           (hour * 3600.0 + minute * 60.0 + second) / 86400.0;
}

double ParseIso8601(const std::string& text, const std::string& field) {
    TimeParser p(text, field);
    if (text.empty()) p.Bad("it is empty");
    const int year = p.Digits(4, "year");
    if (year < 1) p.Bad("the year 0000 is outside 0001..6000");
    if (year > 6000) p.Bad("the year " + std::to_string(year) + " is outside 0001..6000");
    p.Expect('-', "year");
    const int month = p.Digits(2, "month");
    Range(p, "month", month, 1, 12);
    p.Expect('-', "month");
    const int day = p.Digits(2, "day");
    Range(p, "day", day, 1, DaysInMonth(year, month));
    if (!p.Peek('T') && !p.Peek('t') && !p.Peek(' ')) p.Bad("expected 'T' after the date");
    p.Next();
    const int hour = p.Digits(2, "hour");
    Range(p, "hour", hour, 0, 23);
    p.Expect(':', "hour");
    const int minute = p.Digits(2, "minute");
    Range(p, "minute", minute, 0, 59);
    double second = 0.0;
    if (p.Peek(':')) {
        p.Next();
        const int whole = p.Digits(2, "second");
        double fraction = 0.0;
        if (p.Peek('.')) {
            p.Next();
            std::string digits = "0.";
            while (!p.AtEnd() && p.text_[p.pos_] >= '0' && p.text_[p.pos_] <= '9') {
                digits += p.Next();
            }
            if (digits.size() == 2) p.Bad("the fraction of the second needs digits after '.'");
            ParseNumber(digits, &fraction);  // digits only: always a number in [0, 1)
        }
        if (whole == 60) {
            if (hour != 23 || minute != 59) p.Bad("a leap second (60) is only at 23:59");
        } else {
            Range(p, "second", whole, 0, 59);
        }
        second = whole + fraction;
    }
    // The UTC offset.
    int offset_minutes = 0;
    if (p.AtEnd()) p.Bad("no UTC offset (add Z for UTC, or +HH:MM / -HH:MM)");
    const char sign = p.Next();
    if (sign == 'Z' || sign == 'z') {
        // UTC
    } else if (sign == '+' || sign == '-') {
        const int oh = p.Digits(2, "offset hours");
        Range(p, "offset hours", oh, 0, 23);
        int om = 0;
        if (p.Peek(':')) {
            p.Next();
            om = p.Digits(2, "offset minutes");
        } else if (!p.AtEnd()) {
            om = p.Digits(2, "offset minutes");
        }
        Range(p, "offset minutes", om, 0, 59);
        offset_minutes = (sign == '-' ? -1 : 1) * (oh * 60 + om);
    } else {
        p.Bad(std::string("unexpected '") + sign +
              "' where the UTC offset (Z, +HH:MM, -HH:MM) goes");
    }
    if (!p.AtEnd()) p.Bad("unexpected text after the UTC offset");
    // Local time minus the offset is UTC.
    return JulianDayFromUtc(year, month, day, hour, minute, second) - offset_minutes / 1440.0;
}

double DeltaTSeconds(double julian_day_ut) {
    // The decimal year of Espenak & Meeus, y = year + (month - 0.5) / 12, is
    // ~the middle of the month; the continuous year at the instant is used
    // here (2000.0 = JD 2451544.5, 365.2425 days a year).
    const double y = 2000.0 + (julian_day_ut - 2451544.5) / 365.2425;
    double t;
    if (y < -500.0 || y >= 2150.0) {
        const double u = (y - 1820.0) / 100.0;
        return -20.0 + 32.0 * u * u;
    }
    if (y < 1900.0) {
        // Outside the range atmos claims; the long-term parabola of the same
        // paper (within a few minutes of the record before 1900).
        const double u = (y - 1820.0) / 100.0;
        return -20.0 + 32.0 * u * u;
    }
    if (y < 1920.0) {
        t = y - 1900.0;
        return -2.79 + t * (1.494119 + t * (-0.0598939 + t * (0.0061966 - 0.000197 * t)));
    }
    if (y < 1941.0) {
        t = y - 1920.0;
        return 21.20 + t * (0.84493 + t * (-0.076100 + 0.0020936 * t));
    }
    if (y < 1961.0) {
        t = y - 1950.0;
        return 29.07 + 0.407 * t - t * t / 233.0 + t * t * t / 2547.0;
    }
    if (y < 1986.0) {
        t = y - 1975.0;
        return 45.45 + 1.067 * t - t * t / 260.0 - t * t * t / 718.0;
    }
    if (y < 2005.0) {
        t = y - 2000.0;
        return 63.86 + t * (0.3345 + t * (-0.060374 +
                                          t * (0.0017275 + t * (0.000651814 + t * 0.00002373599))));
    }
    if (y < 2050.0) {
        t = y - 2000.0;
        return 62.92 + 0.32217 * t + 0.005589 * t * t;
    }
    const double u = (y - 1820.0) / 100.0;
    return -20.0 + 32.0 * u * u - 0.5628 * (2150.0 - y);
}

SunPosition ComputeSunPosition(double julian_day_ut, const SunObserver& observer,
                               const SunPositionSettings& settings, SunPositionTrace* trace) {
    SunPositionTrace s;
    const double delta_t =
        std::isnan(settings.delta_t_s) ? DeltaTSeconds(julian_day_ut) : settings.delta_t_s;
    // 3.1: Julian days and centuries (eqs. 5-8).
    s.jd = julian_day_ut;
    s.jde = s.jd + delta_t / 86400.0;
    s.jc = (s.jd - 2451545.0) / 36525.0;
    s.jce = (s.jde - 2451545.0) / 36525.0;
    s.jme = s.jce / 10.0;
    // 3.2: the Earth's heliocentric longitude, latitude and radius (eqs. 9-12).
    SumEachTable(s.jme, s.l_terms, spa::kL0, spa::kL1, spa::kL2, spa::kL3, spa::kL4, spa::kL5);
    SumEachTable(s.jme, s.b_terms, spa::kB0, spa::kB1);
    SumEachTable(s.jme, s.r_terms, spa::kR0, spa::kR1, spa::kR2, spa::kR3, spa::kR4);
    s.l = Wrap360(Deg(Series(s.l_terms, 6, s.jme)));
    s.b = Deg(Series(s.b_terms, 2, s.jme));
    s.r_au = Series(s.r_terms, 5, s.jme);
    // 3.3: geocentric longitude and latitude (eqs. 13-14).
    s.theta = Wrap360(s.l + 180.0);
    s.beta = -s.b;
    // 3.4: nutation (eqs. 15-23).
    const double j = s.jce;
    s.x[0] = 297.85036 + 445267.111480 * j - 0.0019142 * j * j + j * j * j / 189474.0;
    s.x[1] = 357.52772 + 35999.050340 * j - 0.0001603 * j * j - j * j * j / 300000.0;
    s.x[2] = 134.96298 + 477198.867398 * j + 0.0086972 * j * j + j * j * j / 56250.0;
    s.x[3] = 93.27191 + 483202.017538 * j - 0.0036825 * j * j + j * j * j / 327270.0;
    s.x[4] = 125.04452 - 1934.136261 * j + 0.0020708 * j * j + j * j * j / 450000.0;
    double sum_psi = 0.0, sum_eps = 0.0;
    for (const spa::NutationTerm& n : spa::kNutation) {
        double arg = 0.0;
        for (int k = 0; k < 5; ++k) arg += s.x[k] * n.y[k];
        sum_psi += (n.a + n.b * j) * SinD(arg);
        sum_eps += (n.c + n.d * j) * CosD(arg);
    }
    s.delta_psi = sum_psi / 36000000.0;
    s.delta_epsilon = sum_eps / 36000000.0;
    // 3.5: true obliquity of the ecliptic (eqs. 24-25), U = JME / 10.
    const double u = s.jme / 10.0;
    static const double kEps[11] = {84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67,
                                    -39.05,    7.12,     27.87, 5.79,    2.45};
    double eps0 = 0.0;
    for (int k = 10; k >= 0; --k) eps0 = eps0 * u + kEps[k];
    s.epsilon0_arcsec = eps0;
    s.epsilon = eps0 / 3600.0 + s.delta_epsilon;
    // 3.6-3.7: aberration and the apparent sun longitude (eqs. 26-27).
    s.delta_tau = -20.4898 / (3600.0 * s.r_au);
    s.lambda = s.theta + s.delta_psi + s.delta_tau;
    // 3.8: apparent sidereal time at Greenwich (eqs. 28-29).
    s.nu0 = Wrap360(280.46061837 + 360.98564736629 * (s.jd - 2451545.0) +
                    0.000387933 * s.jc * s.jc - s.jc * s.jc * s.jc / 38710000.0);
    s.nu = s.nu0 + s.delta_psi * CosD(s.epsilon);
    // 3.9-3.10: geocentric right ascension and declination (eqs. 30-31).
    s.alpha = Wrap360(
        Deg(std::atan2(SinD(s.lambda) * CosD(s.epsilon) - std::tan(s.beta * kRad) * SinD(s.epsilon),
                       CosD(s.lambda))));
    s.delta = Deg(std::asin(SinD(s.beta) * CosD(s.epsilon) +
                            CosD(s.beta) * SinD(s.epsilon) * SinD(s.lambda)));
    // 3.11: observer local hour angle (eq. 32), longitude east positive.
    s.h = Wrap360(s.nu + observer.longitude_deg - s.alpha);
    // 3.12: topocentric right ascension and declination (eqs. 33-39).
    s.xi = 8.794 / (3600.0 * s.r_au);
    const double phi = observer.latitude_deg;
    const double uu = std::atan(0.99664719 * std::tan(phi * kRad));
    const double xx = std::cos(uu) + observer.height_m / 6378140.0 * CosD(phi);
    const double yy = 0.99664719 * std::sin(uu) + observer.height_m / 6378140.0 * SinD(phi);
    const double denom = CosD(s.delta) - xx * SinD(s.xi) * CosD(s.h);
    const double d_alpha = std::atan2(-xx * SinD(s.xi) * SinD(s.h), denom);
    s.delta_alpha = Deg(d_alpha);
    s.alpha_prime = s.alpha + s.delta_alpha;
    s.delta_prime = Deg(std::atan2((SinD(s.delta) - yy * SinD(s.xi)) * std::cos(d_alpha), denom));
    // 3.13: topocentric local hour angle (eq. 40).
    s.h_prime = s.h - s.delta_alpha;
    // 3.14: topocentric elevation (eqs. 41-44).
    double sin_e0 =
        SinD(phi) * SinD(s.delta_prime) + CosD(phi) * CosD(s.delta_prime) * CosD(s.h_prime);
    sin_e0 = std::fmax(-1.0, std::fmin(1.0, sin_e0));
    s.e0 = Deg(std::asin(sin_e0));
    s.delta_e = 0.0;
    // Refraction (eq. 42: Saemundsson's true-to-apparent formula, Meeus 1998
    // eq. 16.4, scaled by P/1010 mbar and 283/(273+T)), applied as the SPA's
    // code does only while the sun's upper limb can be above the horizon
    // (e0 >= -(0.26667 + 0.5667) degrees: the sun's radius plus the refraction
    // at the horizon).
    if (settings.refraction && s.e0 >= -(0.26667 + 0.5667)) {
        s.delta_e = settings.pressure_mbar / 1010.0 * 283.0 / (273.0 + settings.temperature_c) *
                    1.02 / (60.0 * std::tan((s.e0 + 10.3 / (s.e0 + 5.11)) * kRad));
    }
    s.e = s.e0 + s.delta_e;
    // 3.15: topocentric azimuth (eqs. 45-46), from north, eastward.
    s.gamma =
        Wrap360(Deg(std::atan2(SinD(s.h_prime), CosD(s.h_prime) * SinD(phi) -
                                                    std::tan(s.delta_prime * kRad) * CosD(phi))));
    s.phi = Wrap360(s.gamma + 180.0);
    if (trace != nullptr) *trace = s;
    SunPosition out;
    out.elevation_deg = s.e;
    out.zenith_deg = 90.0 - s.e;
    out.azimuth_deg = s.phi;
    out.refraction_deg = s.delta_e;
    return out;
}

void CheckSunObserver(const SunObserver& o, const std::string& where) {
    CheckValue(where, "latitude", o.latitude_deg, -90.0, 90.0, " degrees");
    CheckValue(where, "longitude", o.longitude_deg, -180.0, 180.0, " degrees");
    CheckValue(where, "height", o.height_m, -1000.0, 100000.0, " m");
}

void CheckSunSettings(const SunPositionSettings& s, const std::string& where) {
    if (!std::isnan(s.delta_t_s))
        CheckValue(where, "delta-t", s.delta_t_s, -1000.0, 100000.0, " s");
    if (s.refraction) {
        CheckValue(where, "pressure", s.pressure_mbar, 0.0, 2000.0, " mbar");
        CheckValue(where, "temperature", s.temperature_c, -100.0, 100.0, " C");
    }
}

SunTimeSpec ParseSunTimeSpec(const std::string& spec) {
    const std::string where = "--sun";
    static const char* const kKeys[] = {"time",     "latitude",    "longitude", "height",
                                        "pressure", "temperature", "delta-t"};
    const std::string key_list =
        "time, latitude, longitude, height, pressure, temperature, delta-t";
    SunTimeSpec out;
    bool seen[7] = {false, false, false, false, false, false, false};
    size_t start = 0;
    while (start <= spec.size()) {
        size_t end = spec.find(',', start);
        if (end == std::string::npos) end = spec.size();
        const std::string item = spec.substr(start, end - start);
        start = end + 1;
        const size_t eq = item.find('=');
        if (eq == std::string::npos) {
            Fail(where, ": '", item, "' is not KEY=VALUE (keys: ", key_list, ")");
        }
        const std::string key = item.substr(0, eq);
        const std::string value = item.substr(eq + 1);
        int index = -1;
        for (int k = 0; k < 7; ++k) {
            if (key == kKeys[k]) index = k;
        }
        if (index < 0) Fail(where, ": unknown key '", key, "' (keys: ", key_list, ")");
        if (seen[index]) Fail(where, ": key '", key, "' is given twice");
        seen[index] = true;
        if (index == 0) {
            out.julian_day_ut = ParseIso8601(value, where + ": time");
            continue;
        }
        double v = 0.0;
        const NumberError e = ParseNumber(value, &v);
        if (e != NumberError::kNone) {
            Fail(where, ": ", key, " '", value, "' ", NumberErrorText(e));
        }
        switch (index) {
            case 1:
                out.observer.latitude_deg = v;
                break;
            case 2:
                out.observer.longitude_deg = v;
                break;
            case 3:
                out.observer.height_m = v;
                break;
            case 4:
                out.settings.pressure_mbar = v;
                out.settings.refraction = true;
                break;
            case 5:
                out.settings.temperature_c = v;
                out.settings.refraction = true;
                break;
            default:
                out.settings.delta_t_s = v;
                break;
        }
    }
    for (int k = 0; k < 3; ++k) {
        if (!seen[k]) {
            Fail(where, ": missing key '", kKeys[k],
                 "' (a date-and-place sun needs time=ISO-8601,latitude=DEG,longitude=DEG)");
        }
    }
    CheckSunObserver(out.observer, where);
    CheckSunSettings(out.settings, where);
    return out;
}

SunPosition SunFromTimeSpec(const std::string& spec) {
    const SunTimeSpec s = ParseSunTimeSpec(spec);
    return ComputeSunPosition(s.julian_day_ut, s.observer, s.settings);
}

}  // namespace atmos
