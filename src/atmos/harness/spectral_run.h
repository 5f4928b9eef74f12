// atmos: spectral rendering and sampling (docs/architecture.md "Spectral rendering").
//
// The models compute three channels. A spectral run evaluates a SpectralAtmosphere
// at the wavelengths in batches of three (the last batch repeats its last
// wavelength), prepares a fresh model per batch and renders or samples it: the
// models are unchanged, as in Bruneton 2017's precomputation of N wavelengths in
// batches. Monte Carlo models use the same seed in every batch (their paths are
// the same random numbers at every wavelength; no checkpoints or variance).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/spectral.h"

namespace atmos {

// N values per pixel: values[(y * width + x) * nm.size() + i].
struct SpectralImage {
    int width = 0;
    int height = 0;
    std::vector<double> nm;
    std::vector<float> values;
};

// Prepare()s a model for one batch's atmosphere (the CLI passes its PrepareModel).
using PrepareFunction = std::function<void(const AtmosphereParameters&, Model*)>;

// Fails (atmos::Error) for models without per-wavelength coefficients (preetham,
// neural: their inputs are not an atmosphere's coefficients).
bool HasSpectralForm(const ModelInfo& info);
void RequireSpectralModel(const ModelInfo& info);

// Renders `request` at each wavelength: radiance x the solar spectrum (the
// pixel's irradiance), in the solar spectrum's units per steradian.
SpectralImage RenderSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                             const std::vector<double>& nm, const RenderRequest& request,
                             const PrepareFunction& prepare);

// Spectral radiance of each query at each wavelength, [q * nm.size() + i]: the
// sample's radiance per unit irradiance x the solar spectrum (no sun disc, no
// ground). Monte Carlo models use `monte_carlo`.
std::vector<double> SampleSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                   const std::vector<double>& nm,
                                   const std::vector<SampleQuery>& queries,
                                   const MonteCarloSettings& monte_carlo,
                                   const PrepareFunction& prepare);

enum class ColourOutput { kSrgb, kXyz };
ColourOutput ParseColourOutput(const std::string& text);  // "srgb" or "xyz"

// The image's colour: XYZ through the CIE 1931 functions (weights
// WavelengthWeights) divided by CieYIntegral() (106.86 nm), so that a flat
// spectrum of value L has Y = L (the units of the spectrum: x 683 x 106.86 for
// cd m^-2 when it is in W m^-2 sr^-1 nm^-1), as XYZ or linear sRGB with `white`.
Image SpectralToColour(const SpectralImage& image, ColourOutput colour, WhitePoint white);

// The spectral EXR of Fichet, Pacanowski and Wilkie, "An OpenEXR Layout for
// Spectral Images", JCGT 10(3), 2021: one float channel per wavelength named
// "S0.<nm with a comma for the decimal point>nm" (emissive, e.g. "S0.371,75nm"),
// the attributes spectralLayoutVersion = "1.0" and emissiveUnits =
// "W.m^-2.sr^-1", plus R, G, B (linear sRGB, D65) for viewers.
void WriteSpectralExr(const SpectralImage& image, const std::string& path);
std::string SpectralExrChannelName(double nm);

}  // namespace atmos
