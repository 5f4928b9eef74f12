// atmos: spectral rendering and sampling in batches of three wavelengths.
#include "harness/spectral_run.h"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "io/image_formats.h"
#include "render/progressive.h"

namespace atmos {

namespace {

// The three wavelengths of batch b (the last batch repeats its last wavelength).
void BatchWavelengths(const std::vector<double>& nm, size_t b, double out[3]) {
    for (size_t c = 0; c < 3; ++c) out[c] = nm[std::min(3 * b + c, nm.size() - 1)];
}

std::unique_ptr<Model> PrepareBatch(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                    const double l[3], const PrepareFunction& prepare,
                                    AtmosphereParameters* batch) {
    *batch = atmosphere.AtWavelengths(l[0], l[1], l[2]);
    std::unique_ptr<Model> model = CreateModel(spec);
    RequireSpectralModel(model->Info());
    prepare(*batch, model.get());
    return model;
}

}  // namespace

bool HasSpectralForm(const ModelInfo& info) {
    return info.name != "preetham" && info.name != "neural";
}

void RequireSpectralModel(const ModelInfo& info) {
    if (!HasSpectralForm(info)) {
        Fail("model ", info.name,
             " has no per-wavelength form in atmos (its inputs are not an atmosphere's "
             "coefficients); --wavelengths takes the physical models");
    }
}

SpectralImage RenderSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                             const std::vector<double>& nm, const RenderRequest& request,
                             const PrepareFunction& prepare) {
    SpectralImage out;
    out.width = request.width;
    out.height = request.height;
    out.nm = nm;
    const size_t n = nm.size();
    const size_t pixels = static_cast<size_t>(request.width) * request.height;
    out.values.assign(pixels * n, 0.0f);
    for (size_t b = 0; 3 * b < n; ++b) {
        double l[3];
        BatchWavelengths(nm, b, l);
        AtmosphereParameters batch;
        std::unique_ptr<Model> model = PrepareBatch(spec, atmosphere, l, prepare, &batch);
        RenderRequest r = request;
        r.checkpoint.clear();
        r.resume = false;
        r.variance = nullptr;
        r.report = nullptr;
        Image image;
        model->Render(r, &image);
        for (size_t p = 0; p < pixels; ++p) {
            for (size_t c = 0; c < 3 && 3 * b + c < n; ++c) {
                out.values[p * n + 3 * b + c] = image.data()[p * 3 + c];
            }
        }
    }
    return out;
}

std::vector<double> SampleSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                   const std::vector<double>& nm,
                                   const std::vector<SampleQuery>& queries,
                                   const MonteCarloSettings& monte_carlo,
                                   const PrepareFunction& prepare) {
    const size_t n = nm.size();
    std::vector<double> out(queries.size() * n, 0.0);
    for (size_t b = 0; 3 * b < n; ++b) {
        double l[3];
        BatchWavelengths(nm, b, l);
        AtmosphereParameters batch;
        std::unique_ptr<Model> model = PrepareBatch(spec, atmosphere, l, prepare, &batch);
        const std::vector<SampleAnswer> answers =
            model->Info().capabilities.stochastic ? SampleMonteCarlo(*model, queries, monte_carlo)
                                                  : model->Sample(queries);
        for (size_t q = 0; q < queries.size(); ++q) {
            for (size_t c = 0; c < 3 && 3 * b + c < n; ++c) {
                const int ci = static_cast<int>(c);
                out[q * n + 3 * b + c] =
                    static_cast<double>(answers[q].radiance[ci]) * batch.solar_irradiance[ci];
            }
        }
    }
    return out;
}

ColourOutput ParseColourOutput(const std::string& text) {
    if (text == "srgb") return ColourOutput::kSrgb;
    if (text == "xyz") return ColourOutput::kXyz;
    Fail("--colour '", text, "': expected srgb or xyz");
}

Image SpectralToColour(const SpectralImage& image, ColourOutput colour, WhitePoint white) {
    Image out(image.width, image.height);
    const size_t n = image.nm.size();
    std::vector<double> weights = WavelengthWeights(image.nm);
    const double y_integral = CieYIntegral();
    for (double& w : weights) w /= y_integral;
    std::vector<double> spectrum(n);
    const size_t pixels = static_cast<size_t>(image.width) * image.height;
    for (size_t p = 0; p < pixels; ++p) {
        for (size_t i = 0; i < n; ++i) spectrum[i] = image.values[p * n + i];
        Vec3d c = SpectrumToXyz(image.nm, weights, spectrum.data());
        if (colour == ColourOutput::kSrgb) c = XyzToLinearSrgb(c, white);
        for (int k = 0; k < 3; ++k) {
            // Out-of-gamut sRGB (negative) is clipped to 0: pixels are never negative.
            out.data()[p * 3 + static_cast<size_t>(k)] = static_cast<float>(std::max(c[k], 0.0));
        }
    }
    return out;
}

std::string SpectralExrChannelName(double nm) {
    std::string label = WavelengthLabel(nm);
    std::replace(label.begin(), label.end(), '.', ',');
    return "S0." + label + "nm";
}

void WriteSpectralExr(const SpectralImage& image, const std::string& path) {
    const size_t n = image.nm.size();
    std::vector<std::string> names;
    for (double l : image.nm) names.push_back(SpectralExrChannelName(l));
    names.insert(names.end(), {"R", "G", "B"});
    const Image rgb = SpectralToColour(image, ColourOutput::kSrgb, WhitePoint::kD65);
    const size_t pixels = static_cast<size_t>(image.width) * image.height;
    std::vector<float> values(pixels * (n + 3));
    for (size_t p = 0; p < pixels; ++p) {
        for (size_t i = 0; i < n; ++i) values[p * (n + 3) + i] = image.values[p * n + i];
        for (size_t k = 0; k < 3; ++k) values[p * (n + 3) + n + k] = rgb.data()[p * 3 + k];
    }
    detail::WriteMultiChannelExr(
        path, image.width, image.height, names, values,
        {{"spectralLayoutVersion", "1.0"}, {"emissiveUnits", "W.m^-2.sr^-1"}});
}

}  // namespace atmos
