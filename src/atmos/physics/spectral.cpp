// atmos: spectra, the spectral atmosphere's AtWavelengths, wavelength lists and colour.
//
// Sources: Penndorf 1957 (J. Opt. Soc. Am. 47(2) 176-182) eqs. (2), (3), (5a) for the
// Rayleigh law; CIE 1931 2-degree observer (data/spectra/cie1931-2deg.csv);
// IEC 61966-2-1 (sRGB) for the XYZ -> linear sRGB matrix; the Bradford cone
// response matrix (Lam 1985, as in ICC.1 Annex E) for the E -> D65 adaptation.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/embedded_presets.h"
#include "atmos/error.h"
#include "atmos/number.h"
#include "atmos/spectral.h"

namespace atmos {

namespace {

double Interpolate(const std::vector<double>& nm, const std::vector<double>& values, double x) {
    if (nm.empty()) return 0.0;
    if (x <= nm.front()) return values.front();
    if (x >= nm.back()) return values.back();
    const size_t i = static_cast<size_t>(std::upper_bound(nm.begin(), nm.end(), x) - nm.begin());
    const double t = (x - nm[i - 1]) / (nm[i] - nm[i - 1]);
    if (t == 0.0) return values[i - 1];
    return values[i - 1] + t * (values[i] - values[i - 1]);
}

struct DataTable {
    std::vector<double> nm;
    std::vector<std::vector<double>> columns;
};

DataTable ParseDataTable(const char* name, const char* text) {
    DataTable table;
    std::istringstream in(text);
    std::string line;
    bool header = false;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        if (!header) {
            header = true;
            continue;
        }
        std::vector<double> row;
        std::stringstream fields(line);
        std::string field;
        while (std::getline(fields, field, ',')) {
            double v = 0.0;
            if (ParseNumber(field, &v) != NumberError::kNone) {
                Fail("spectral table '", name, "': '", field, "' is not a number");
            }
            row.push_back(v);
        }
        if (row.size() < 2) Fail("spectral table '", name, "': a row needs nm and a value");
        if (table.columns.empty()) table.columns.resize(row.size() - 1);
        if (row.size() != table.columns.size() + 1) {
            Fail("spectral table '", name, "': rows of different lengths");
        }
        table.nm.push_back(row[0]);
        for (size_t c = 1; c < row.size(); ++c) table.columns[c - 1].push_back(row[c]);
    }
    return table;
}

const DataTable& FindTable(const std::string& name) {
    static std::mutex mutex;
    static std::map<std::string, DataTable> cache;
    const std::lock_guard<std::mutex> lock(mutex);
    const auto it = cache.find(name);
    if (it != cache.end()) return it->second;
    for (int i = 0; i < detail::kEmbeddedSpectrumCount; ++i) {
        if (name == detail::kEmbeddedSpectra[i].name) {
            return cache[name] = ParseDataTable(detail::kEmbeddedSpectra[i].name,
                                                detail::kEmbeddedSpectra[i].json);
        }
    }
    std::string names;
    for (const std::string& n : SpectralDataNames()) names += (names.empty() ? "" : ", ") + n;
    Fail("unknown spectral table '", name, "' (tables: ", names, ")");
}

struct Cmf {
    std::vector<double> nm, x, y, z;
};

const Cmf& CieTable() {
    static const Cmf cmf = [] {
        Cmf c;
        SpectralDataTable("cie1931-2deg", 0, &c.nm, &c.x);
        SpectralDataTable("cie1931-2deg", 1, &c.nm, &c.y);
        SpectralDataTable("cie1931-2deg", 2, &c.nm, &c.z);
        return c;
    }();
    return cmf;
}

using Matrix3 = double[3][3];

Vec3d Multiply(const Matrix3& m, const Vec3d& v) {
    return Vec3d(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                 m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                 m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z);
}

// IEC 61966-2-1: XYZ (D65) -> linear sRGB.
constexpr Matrix3 kXyzToSrgb = {
    {3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}};
// Bradford cone responses.
constexpr Matrix3 kBradford = {
    {0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};

void Invert(const Matrix3& m, Matrix3& inv) {
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            inv[r][c] = (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det;
        }
    }
}

}  // namespace

double Spectrum::At(double nm) const {
    double result = 1.0;
    for (const SpectralTerm& t : terms) {
        switch (t.kind) {
            case SpectralTerm::Kind::kConstant:
                result *= t.value;
                break;
            case SpectralTerm::Kind::kTable:
                result *= t.value * Interpolate(t.nm, t.values, nm);
                break;
            case SpectralTerm::Kind::kPowerLaw:
                result *= t.value * std::pow(nm / t.reference_nm, -t.exponent);
                break;
            case SpectralTerm::Kind::kPenndorf:
                result *= t.value * PenndorfRayleigh(nm);
                break;
        }
    }
    return result;
}

Spectrum Spectrum::Constant(double value) {
    Spectrum s;
    SpectralTerm t;
    t.value = value;
    s.terms.push_back(t);
    return s;
}

Spectrum Spectrum::Table(std::vector<double> nm, std::vector<double> values, double scale) {
    Spectrum s;
    SpectralTerm t;
    t.kind = SpectralTerm::Kind::kTable;
    t.value = scale;
    t.nm = std::move(nm);
    t.values = std::move(values);
    s.terms.push_back(t);
    return s;
}

Spectrum Spectrum::FromRgb(const Vec3d& rgb) {
    // Increasing wavelength: blue (440), green (550), red (680).
    return Table({kRgbWavelengths[2], kRgbWavelengths[1], kRgbWavelengths[0]},
                 {rgb.z, rgb.y, rgb.x});
}

double PenndorfRayleigh(double nm) {
    const double sigma2 = 1.0 / ((nm * 1e-3) * (nm * 1e-3));  // (1/um)^2
    const double n_minus_1 = (6432.8 + 2949810.0 / (146.0 - sigma2) + 25540.0 / (41.0 - sigma2)) *
                             1e-8;  // Penndorf (5a), 15 deg C, 760 mm Hg
    const double n = 1.0 + n_minus_1;
    const double n2m1 = n * n - 1.0;
    const double n2p2 = n * n + 2.0;
    constexpr double kNs = 2.547e25;  // molecules per m^3, 15 deg C, 1013.25 hPa
    constexpr double kRho = 0.035;    // depolarisation factor
    const double lambda_m = nm * 1e-9;
    const double lambda4 = lambda_m * lambda_m * lambda_m * lambda_m;
    const double pi3 = kPi * kPi * kPi;
    return 24.0 * pi3 * n2m1 * n2m1 / (lambda4 * kNs * n2p2 * n2p2) * (6.0 + 3.0 * kRho) /
           (6.0 - 7.0 * kRho);
}

AtmosphereParameters SpectralAtmosphere::AtWavelengths(double l0, double l1, double l2) const {
    AtmosphereParameters a = base;
    const double l[3] = {l0, l1, l2};
    for (int c = 0; c < 3; ++c) {
        a.rayleigh_scattering[c] = rayleigh_scattering.At(l[c]);
        a.mie_scattering[c] = mie_scattering.At(l[c]);
        a.mie_extinction[c] = mie_extinction.At(l[c]);
        a.absorption_extinction[c] = absorption_extinction.At(l[c]);
        a.ground_albedo[c] = ground_albedo.At(l[c]);
        a.solar_irradiance[c] = solar_irradiance.At(l[c]);
    }
    ValidateAtmosphere(a);
    return a;
}

void SpectralDataTable(const std::string& name, int column, std::vector<double>* nm,
                       std::vector<double>* values) {
    const DataTable& table = FindTable(name);
    if (column < 0 || column >= static_cast<int>(table.columns.size())) {
        Fail("spectral table '", name, "' has no value column ", column);
    }
    *nm = table.nm;
    *values = table.columns[static_cast<size_t>(column)];
}

std::vector<std::string> SpectralDataNames() {
    return detail::SortedNames(detail::kEmbeddedSpectra, detail::kEmbeddedSpectrumCount);
}

std::vector<double> ParseWavelengths(const std::string& text) {
    auto number = [&](const std::string& item) {
        double v = 0.0;
        const NumberError e = ParseNumber(item, &v);
        if (e != NumberError::kNone) {
            Fail("--wavelengths '", text, "': '", item, "' ", NumberErrorText(e));
        }
        return v;
    };
    std::vector<double> nm;
    const size_t colon = text.find(':');
    if (colon != std::string::npos) {
        const size_t colon2 = text.find(':', colon + 1);
        if (colon2 == std::string::npos || text.find(':', colon2 + 1) != std::string::npos) {
            Fail("--wavelengths '", text, "': expected START:STOP:COUNT or a list a,b,c (nm)");
        }
        const double start = number(text.substr(0, colon));
        const double stop = number(text.substr(colon + 1, colon2 - colon - 1));
        const double count = number(text.substr(colon2 + 1));
        if (count < 1 || count > 1000 || count != std::floor(count)) {
            Fail("--wavelengths '", text, "': COUNT must be an integer in [1, 1000]");
        }
        const int n = static_cast<int>(count);
        if (n == 1 && start != stop) {
            Fail("--wavelengths '", text, "': COUNT 1 needs START = STOP");
        }
        for (int i = 0; i < n; ++i) {
            nm.push_back(n == 1 ? start : start + (stop - start) * i / (n - 1));
        }
    } else {
        std::stringstream ss(text);
        std::string item;
        while (std::getline(ss, item, ',')) nm.push_back(number(item));
    }
    if (nm.empty() || nm.size() > 1000) {
        Fail("--wavelengths '", text, "': give 1 to 1000 wavelengths");
    }
    for (size_t i = 0; i < nm.size(); ++i) {
        if (!(nm[i] >= 200.0 && nm[i] <= 3000.0)) {
            Fail("--wavelengths '", text, "': ", WavelengthLabel(nm[i]),
                 " nm is outside [200, 3000] nm");
        }
        if (i > 0 && !(nm[i] > nm[i - 1])) {
            Fail("--wavelengths '", text, "': the wavelengths must increase strictly");
        }
    }
    return nm;
}

std::string WavelengthLabel(double nm) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), nm);
    return std::string(buffer, result.ptr);
}

std::vector<double> WavelengthWeights(const std::vector<double>& nm) {
    const size_t n = nm.size();
    std::vector<double> w(n, 1.0);
    if (n < 2) return w;
    const double step = (nm.back() - nm.front()) / static_cast<double>(n - 1);
    bool uniform = true;
    for (size_t i = 1; i < n; ++i) {
        if (std::abs(nm[i] - nm[i - 1] - step) > 1e-9 * step) uniform = false;
    }
    for (size_t i = 0; i < n; ++i) {
        if (uniform) {
            w[i] = step;
        } else if (i == 0) {
            w[i] = nm[1] - nm[0];
        } else if (i == n - 1) {
            w[i] = nm[n - 1] - nm[n - 2];
        } else {
            w[i] = 0.5 * (nm[i + 1] - nm[i - 1]);
        }
    }
    return w;
}

Vec3d Cie1931(double nm) {
    const Cmf& c = CieTable();
    if (nm < c.nm.front() || nm > c.nm.back()) return Vec3d(0.0);
    return Vec3d(Interpolate(c.nm, c.x, nm), Interpolate(c.nm, c.y, nm),
                 Interpolate(c.nm, c.z, nm));
}

std::vector<Vec3d> Cie1931At(const std::vector<double>& nm) {
    std::vector<Vec3d> cmf(nm.size());
    for (size_t i = 0; i < nm.size(); ++i) cmf[i] = Cie1931(nm[i]);
    return cmf;
}

Vec3d SpectrumToXyz(const std::vector<Vec3d>& cmf, const std::vector<double>& weights,
                    const double* values, size_t stride) {
    Vec3d xyz(0.0);
    for (size_t i = 0; i < cmf.size(); ++i) {
        const double s = values[i * stride] * weights[i];
        xyz = Vec3d(xyz.x + s * cmf[i].x, xyz.y + s * cmf[i].y, xyz.z + s * cmf[i].z);
    }
    return xyz;
}

Vec3d SpectrumToXyz(const std::vector<double>& nm, const std::vector<double>& weights,
                    const double* values, size_t stride) {
    return SpectrumToXyz(Cie1931At(nm), weights, values, stride);
}

double CieYIntegral() {
    static const double integral = [] {
        const Cmf& c = CieTable();
        const std::vector<double> ones(c.nm.size(), 1.0);
        return SpectrumToXyz(c.nm, WavelengthWeights(c.nm), ones.data()).y;
    }();
    return integral;
}

WhitePoint ParseWhitePoint(const std::string& text) {
    if (text == "d65") return WhitePoint::kD65;
    if (text == "e") return WhitePoint::kE;
    Fail("--white '", text, "': expected d65 or e");
}

Vec3d XyzToLinearSrgb(const Vec3d& xyz, WhitePoint white) {
    if (white == WhitePoint::kD65) return Multiply(kXyzToSrgb, xyz);
    static const auto adapt = [] {
        // M^-1 diag(rho_D65 / rho_E) M, E = (1, 1, 1), D65 = (0.95047, 1, 1.08883).
        const Vec3d e = Multiply(kBradford, Vec3d(1.0));
        const Vec3d d = Multiply(kBradford, Vec3d(0.95047, 1.0, 1.08883));
        Matrix3 inv;
        Invert(kBradford, inv);
        std::vector<double> m(9);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
                double sum = 0.0;
                for (int k = 0; k < 3; ++k) sum += inv[r][k] * (d[k] / e[k]) * kBradford[k][c];
                m[static_cast<size_t>(r * 3 + c)] = sum;
            }
        }
        return m;
    }();
    const Matrix3 m = {{adapt[0], adapt[1], adapt[2]},
                       {adapt[3], adapt[4], adapt[5]},
                       {adapt[6], adapt[7], adapt[8]}};
    return Multiply(kXyzToSrgb, Multiply(m, xyz));
}

}  // namespace atmos
