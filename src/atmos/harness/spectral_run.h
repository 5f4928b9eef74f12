// atmos: spectral rendering and sampling (docs/architecture.md "Spectral rendering").
//
// The models compute three channels. A spectral run evaluates a SpectralAtmosphere
// at the wavelengths in batches of three (SpectralBatches: interleaved by default,
// neighbours on request; a short batch repeats its last wavelength), prepares a fresh model per
// batch and renders or samples it: the models are unchanged, as in Bruneton 2017's precomputation
// of N wavelengths in batches. Monte Carlo models take a seed per batch (SpectralBatching; no
// checkpoints or variance). A Monte Carlo model whose paths carry many wavelengths
// (ModelCapabilities::spectral_paths: the reference's hero-wavelength paths) instead gets all
// of them at once, one Prepare() and one set of paths from the run's seed, where the run has
// more than three wavelengths on the CPU and renders radiance without the sun's disc or a
// noise target (batching does not apply to it).
#pragma once

#include <array>
#include <cstdint>
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

// The random numbers of a Monte Carlo model's batches. kSame: every batch uses
// the run's seed (a pixel's paths are the same random numbers at every
// wavelength: the noise of the N values is correlated, colour noise small,
// luminance as noisy as one batch). kDistinct: batch b uses seed + b * 2^40
// (independent batches: luminance averages the noise of the batches it spans,
// about 4.3 of the 14 batches of 360-818.25 nm for CIE y; colour noise larger).
enum class BatchSeeds { kSame, kDistinct };
BatchSeeds ParseBatchSeeds(const std::string& text);  // "same" or "distinct"
uint64_t BatchSeed(uint64_t seed, size_t batch, BatchSeeds seeds);

// Which wavelengths share a batch. kConsecutive: batch b holds wavelengths 3b,
// 3b+1, 3b+2 (neighbours, as Bruneton 2017 precomputes them). kInterleaved: batch
// b holds b, b+S, b+2S with S = ceil(N/3): three wavelengths spread over the
// range, the stratified companions of hero-wavelength sampling (Wilkie et al.
// 2014, "Hero Wavelength Spectral Sampling"), with the hero swept over the
// batches in turn instead of drawn per path. A deterministic model gives the
// same values either way; for a Monte Carlo model with distinct seeds, the
// wavelengths a colour-matching function spans fall in more independent batches.
enum class BatchLayout { kConsecutive, kInterleaved };
BatchLayout ParseBatchLayout(const std::string& text);  // "consecutive" or "interleaved"

// The default: interleaved batches with distinct seeds, the least noise in colour
// (luminance and chromaticity) at equal time of the four (docs/harness.md "Batch
// layout and seeds", scripts/spectral_noise.py). kPerWavelength: consecutive
// batches with one seed, the least noise in each wavelength's own value (what
// validate scores).
//
// `wide`: a model with wide channel batches (ModelCapabilities::wide_channels;
// deterministic, on the CPU backend) is prepared once for up to
// kMaxWideChannels / 3 batches and evaluates all their channels per ray
// (Model::PrepareWide; bruneton precomputes all the channels at once): the
// same values bit for bit, the geometry computed once per ray (and per texel
// of the precomputation) instead of once per batch. false: one model per
// batch of three, as every other model.
//
// `prepare_wide`: how a wide group's model is prepared. Empty: PrepareWide(
// group) (the model's own precomputation of every channel; `prepare` is not
// called). Else prepare_wide(group, model, prepare), which calls PrepareWide
// itself: with `prepare` to gather each batch's tables through it (the CLI
// does when its table cache holds every batch's tables), or without.
using PrepareFunction = std::function<void(const AtmosphereParameters&, Model*)>;
using WidePrepareFunction = std::function<void(const std::vector<AtmosphereParameters>& group,
                                               Model* model, const PrepareFunction& prepare)>;
struct SpectralBatching {
    BatchSeeds seeds = BatchSeeds::kDistinct;
    BatchLayout layout = BatchLayout::kInterleaved;
    bool wide = true;
    WidePrepareFunction prepare_wide = nullptr;
};
// "wide" or "three" (--channel-batches) as SpectralBatching::wide.
bool ParseChannelBatches(const std::string& text);
// Whether a spectral run of `info`'s model takes the wide path now
// (`batching.wide`, the capability, not Monte Carlo, the CPU backend).
bool UsesWideBatches(const ModelInfo& info, SpectralBatching batching);
inline const SpectralBatching kPerWavelengthBatching{BatchSeeds::kSame, BatchLayout::kConsecutive,
                                                     true};

// The wavelength indices of each batch, ceil(N/3) batches of three; a batch short
// of three repeats its last index (its extra channels are computed, not stored).
std::vector<std::array<size_t, 3>> SpectralBatches(size_t wavelengths, BatchLayout layout);

// PrepareFunction (above): Prepare()s a model for one batch's atmosphere (the
// CLI passes its PrepareModel).

// Fails (atmos::Error) for models without a per-wavelength form (neural: its
// inputs are not an atmosphere's coefficients). Preetham has its own (the CIE
// daylight basis; Model::SetSpectralBatch).
bool HasSpectralForm(const ModelInfo& info);
void RequireSpectralModel(const ModelInfo& info);

// Renders `request` at each wavelength: radiance x the solar spectrum (the
// pixel's irradiance), in the solar spectrum's units per steradian.
SpectralImage RenderSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                             const std::vector<double>& nm, const RenderRequest& request,
                             const PrepareFunction& prepare, SpectralBatching batching = {});

// Renders every request (e.g. the views of a compare, any sizes) at each
// wavelength: one Prepare per batch for all the requests (the batches outer, the
// requests inner, one prepared model alive at a time). render_seconds (optional):
// per request, its render time summed over the batches (Prepare excluded).
// reports (optional, Monte Carlo models): per request, the paths per pixel summed
// over the batches and the largest noise of a batch's three-channel image (each
// batch renders to the request's noise target on its own).
std::vector<SpectralImage> RenderSpectralRequests(
    const ModelSpec& spec, const SpectralAtmosphere& atmosphere, const std::vector<double>& nm,
    const std::vector<RenderRequest>& requests, const PrepareFunction& prepare,
    std::vector<double>* render_seconds = nullptr, std::vector<MonteCarloReport>* reports = nullptr,
    SpectralBatching batching = {});

// Groups of consecutive request indices whose spectral images (width x height x
// wavelengths floats) take at most `max_bytes` together (a request alone may
// exceed it): the callers of RenderSpectralRequests bound their memory so.
std::vector<std::vector<size_t>> SpectralRequestGroups(const std::vector<RenderRequest>& requests,
                                                       size_t wavelengths,
                                                       size_t max_bytes = size_t{1} << 30);

// Spectral radiance of each query at each wavelength, [q * nm.size() + i]: the
// sample's radiance per unit irradiance x the solar spectrum (no sun disc, no
// ground). Monte Carlo models use `monte_carlo`.
std::vector<double> SampleSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                   const std::vector<double>& nm,
                                   const std::vector<SampleQuery>& queries,
                                   const MonteCarloSettings& monte_carlo,
                                   const PrepareFunction& prepare, SpectralBatching batching = {});

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
