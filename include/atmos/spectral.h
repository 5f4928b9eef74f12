// atmos: spectral atmospheres, wavelength lists and colour (CIE 1931 -> XYZ -> sRGB).
//
// Design (docs/architecture.md "Spectral rendering"): every model computes three
// channels from an AtmosphereParameters whose coefficients are Vec3d. A spectral
// atmosphere holds each wavelength-dependent field as a Spectrum (a table or a
// law) and produces the AtmosphereParameters of any three wavelengths
// (AtWavelengths); a spectral render runs the unchanged models once per batch of
// three wavelengths, as Bruneton 2017 precomputes N wavelengths in batches.
//
// An RGB atmosphere file is a three-wavelength one: its channels are the values at
// kRgbWavelengths (680, 550, 440 nm), linearly interpolated in between and held
// constant outside, so AtWavelengths(680, 550, 440) gives back the file's values
// exactly.
#pragma once

#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/math.h"

namespace atmos {

// The wavelengths (nm) of today's red, green and blue channels (DESIGN.md).
constexpr double kRgbWavelengths[3] = {680.0, 550.0, 440.0};

// One factor of a spectrum.
struct SpectralTerm {
    enum class Kind {
        kConstant,  // value
        kTable,     // value * linear interpolation of (nm, values), constant outside
        kPowerLaw,  // value * (lambda / reference_nm)^(-exponent)
        kPenndorf,  // value * Penndorf 1957's Rayleigh coefficient of standard air, 15 deg C (1/m)
    };
    Kind kind = Kind::kConstant;
    double value = 1.0;
    double reference_nm = 1000.0;
    double exponent = 0.0;
    std::vector<double> nm;
    std::vector<double> values;
};

// A function of wavelength: the product of its terms (empty: 1).
struct Spectrum {
    std::vector<SpectralTerm> terms;
    double At(double nm) const;
    static Spectrum Constant(double value);
    static Spectrum Table(std::vector<double> nm, std::vector<double> values, double scale = 1.0);
    // The RGB channels placed at kRgbWavelengths.
    static Spectrum FromRgb(const Vec3d& rgb);
};

struct SpectralAtmosphere {
    // Everything that does not depend on wavelength (radii, density profiles, g,
    // sun radius, mu_s_min); its Vec3d fields are the values at kRgbWavelengths.
    AtmosphereParameters base;
    Spectrum rayleigh_scattering;
    Spectrum mie_scattering;
    Spectrum mie_extinction;
    Spectrum absorption_extinction;
    Spectrum ground_albedo;
    Spectrum solar_irradiance;
    bool spectral = false;  // the file gave at least one field as a spectrum
    std::string name;

    // The three-channel atmosphere of the wavelengths (nm) l0, l1, l2 (validated).
    AtmosphereParameters AtWavelengths(double l0, double l1, double l2) const;
};

// The Rayleigh scattering coefficient of standard air (1/m) at `nm`, 15 deg C and
// 1013.25 hPa: Penndorf 1957 eq. (2)-(3) with the refractive index of his eq. (5a)
// (Edlen 1953), N_s = 2.547e25 m^-3 and the King factor (6 + 3 rho) / (6 - 7 rho),
// rho = 0.035. Agrees with his Table III (scaled to 15 deg C) within 0.07 % over 360-800 nm.
double PenndorfRayleigh(double nm);

// Loads an atmosphere (preset or file, --set overrides) keeping its spectra. RGB
// files give FromRgb spectra (spectral = false). Throws atmos::Error naming the
// file and the field.
SpectralAtmosphere LoadSpectralAtmosphere(const std::string& name_or_path,
                                          const std::vector<std::string>& overrides = {});

// An embedded data table of data/spectra/ ("cie1931-2deg", "astm-g173-etr-10nm", ...):
// its wavelengths and its column `column` (0: the first value column).
void SpectralDataTable(const std::string& name, int column, std::vector<double>* nm,
                       std::vector<double>* values);
std::vector<std::string> SpectralDataNames();

// --wavelengths: "START:STOP:COUNT" (COUNT values from START to STOP inclusive) or
// a comma-separated list, in nm, each in [200, 3000], strictly increasing.
std::vector<double> ParseWavelengths(const std::string& text);
// The shortest decimal that reads back to `nm` ("360", "371.75").
std::string WavelengthLabel(double nm);
// The quadrature weight (nm) of each wavelength: the step of a uniform list, else
// half the distance between the neighbours (the end ones: the distance to the
// one neighbour); 1 for a single wavelength.
std::vector<double> WavelengthWeights(const std::vector<double>& nm);

// CIE 1931 2-degree colour-matching functions at `nm` (linear interpolation of the
// 5 nm table data/spectra/cie1931-2deg.csv; 0 outside 360-830 nm).
Vec3d Cie1931(double nm);

// XYZ of a spectrum sampled at `nm` with `weights`: sum_i S_i cmf(nm_i) w_i.
Vec3d SpectrumToXyz(const std::vector<double>& nm, const std::vector<double>& weights,
                    const double* values, size_t stride = 1);
// Cie1931 at each of `nm`: for many spectra at the same wavelengths, the
// colour-matching functions interpolated once (the form below gives the same
// bits as the one above).
std::vector<Vec3d> Cie1931At(const std::vector<double>& nm);
Vec3d SpectrumToXyz(const std::vector<Vec3d>& cmf, const std::vector<double>& weights,
                    const double* values, size_t stride = 1);

// The integral of the CIE 1931 y function over its table, 360-830 nm (106.86 nm).
double CieYIntegral();

// The white of the XYZ -> linear sRGB conversion. kD65: the sRGB matrix of
// IEC 61966-2-1 as is (an equal-energy spectrum comes out slightly pink);
// kE: Bradford adaptation from the equal-energy white E to D65 first (an
// equal-energy spectrum comes out grey, R = G = B).
enum class WhitePoint { kD65, kE };
WhitePoint ParseWhitePoint(const std::string& text);
Vec3d XyzToLinearSrgb(const Vec3d& xyz, WhitePoint white);

// Luminous efficacy of the photopic luminosity function's peak (lm/W): Y in
// cd m^-2 is 683 sum_i L_i y(nm_i) w_i with L in W m^-2 sr^-1 nm^-1.
constexpr double kMaxLuminousEfficacy = 683.0;

}  // namespace atmos
