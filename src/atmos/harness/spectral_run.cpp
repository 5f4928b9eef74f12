// atmos: spectral rendering and sampling in batches of three wavelengths.
#include "harness/spectral_run.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/image_formats.h"
#include "io/output_path.h"
#include "render/progressive.h"

namespace atmos {

namespace {

// The channels of a batch that store their wavelength: all but the repeats that
// fill a short batch, which SpectralBatches puts last (both layouts' indices grow
// with the channel), so a prefix.
size_t StoredChannels(const std::array<size_t, 3>& batch) {
    size_t count = 1;
    while (count < 3 && batch[count] != batch[count - 1]) ++count;
    return count;
}

// Calls each(b, indices, stored, model, batch) for every batch b of three of
// `nm` (SpectralBatches: their indices in `nm`, StoredChannels), with the model
// of `spec` given the batch's wavelengths and prepared (`prepare`) for
// `batch`, the atmosphere at them.
template <typename F>
void ForEachPreparedBatch(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                          const std::vector<double>& nm, BatchLayout layout,
                          const PrepareFunction& prepare, F each) {
    const std::vector<std::array<size_t, 3>> batches = SpectralBatches(nm.size(), layout);
    for (size_t b = 0; b < batches.size(); ++b) {
        const double l[3] = {nm[batches[b][0]], nm[batches[b][1]], nm[batches[b][2]]};
        const size_t stored = StoredChannels(batches[b]);
        AtmosphereParameters batch = atmosphere.AtWavelengths(l[0], l[1], l[2]);
        std::unique_ptr<Model> model = CreateModel(spec);
        RequireSpectralModel(model->Info());
        model->SetSpectralBatch(atmosphere, l);
        prepare(batch, model.get());
        each(b, batches[b], stored, *model, batch);
    }
}

// The wide path (SpectralBatching::wide): calls each(indices, stored, model,
// batches) for groups of at most kMaxWideChannels / 3 consecutive batches of
// SpectralBatches, with one model of `spec` prepared for all of them
// (PrepareWide, or batching.prepare_wide with `prepare`): `indices[g]` and `stored[g]` are the
// g-th batch's, `batches[g]` its atmosphere; the model's channel 3g + c is that batch's channel c.
template <typename F>
void ForEachWideGroup(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                      const std::vector<double>& nm, const SpectralBatching& batching,
                      const PrepareFunction& prepare, F each) {
    const std::vector<std::array<size_t, 3>> batches = SpectralBatches(nm.size(), batching.layout);
    const size_t per_group = static_cast<size_t>(kMaxWideChannels / 3);
    for (size_t first = 0; first < batches.size(); first += per_group) {
        const size_t count = std::min(per_group, batches.size() - first);
        std::vector<std::array<size_t, 3>> indices(batches.begin() + first,
                                                   batches.begin() + first + count);
        std::vector<size_t> stored;
        std::vector<AtmosphereParameters> group;
        for (const std::array<size_t, 3>& b : indices) {
            stored.push_back(StoredChannels(b));
            group.push_back(atmosphere.AtWavelengths(nm[b[0]], nm[b[1]], nm[b[2]]));
        }
        std::unique_ptr<Model> model = CreateModel(spec);
        RequireSpectralModel(model->Info());
        if (batching.prepare_wide) {
            batching.prepare_wide(group, model.get(), prepare);
        } else {
            model->PrepareWide(group);
        }
        each(indices, stored, *model, group);
    }
}

// A Monte Carlo model whose paths carry many wavelengths at once
// (ModelCapabilities::spectral_paths, hero-wavelength sampling: docs/models/reference.md)
// takes all of a run's wavelengths in one set of paths: the model gets them
// (SetSpectralPaths) and one Prepare() with the atmosphere at the shortest, the
// middle and the longest of them. Only where that is the same work as the
// batches: more than one batch, on the CPU, radiance (`renders`: without the
// sun's disc or a noise target, which the batches' progressive driver
// provides). Null: the batches.
std::unique_ptr<Model> SpectralPathsModel(const ModelSpec& spec,
                                          const SpectralAtmosphere& atmosphere,
                                          const std::vector<double>& nm,
                                          const std::vector<RenderRequest>* renders,
                                          const PrepareFunction& prepare) {
    if (nm.size() <= 3 || CurrentBackend() != Backend::kCpu) return nullptr;
    if (renders) {
        for (const RenderRequest& r : *renders) {
            if (r.quantity != Quantity::kRadiance || r.sun_disc ||
                r.monte_carlo.noise_target > 0.0) {
                return nullptr;
            }
        }
    }
    std::unique_ptr<Model> model = CreateModel(spec);
    const ModelCapabilities& caps = model->Info().capabilities;
    if (!caps.stochastic || !caps.spectral_paths) return nullptr;
    std::vector<double> sorted = nm;
    std::sort(sorted.begin(), sorted.end());
    model->SetSpectralPaths(atmosphere, nm);
    prepare(atmosphere.AtWavelengths(sorted.front(), sorted[sorted.size() / 2], sorted.back()),
            model.get());
    return model;
}

}  // namespace

bool ParseChannelBatches(const std::string& text) {
    if (text == "wide") return true;
    if (text == "three") return false;
    Fail("--channel-batches '", text, "': expected wide or three");
}

bool UsesWideBatches(const ModelInfo& info, SpectralBatching batching) {
    return batching.wide && info.capabilities.wide_channels && !info.capabilities.stochastic &&
           CurrentBackend() == Backend::kCpu;
}

BatchSeeds ParseBatchSeeds(const std::string& text) {
    if (text == "same") return BatchSeeds::kSame;
    if (text == "distinct") return BatchSeeds::kDistinct;
    Fail("--batch-seeds '", text, "': expected same or distinct");
}

BatchLayout ParseBatchLayout(const std::string& text) {
    if (text == "consecutive") return BatchLayout::kConsecutive;
    if (text == "interleaved") return BatchLayout::kInterleaved;
    Fail("--batch-layout '", text, "': expected consecutive or interleaved");
}

std::vector<std::array<size_t, 3>> SpectralBatches(size_t wavelengths, BatchLayout layout) {
    std::vector<std::array<size_t, 3>> batches;
    if (wavelengths == 0) return batches;
    const size_t count = (wavelengths + 2) / 3;
    for (size_t b = 0; b < count; ++b) {
        std::array<size_t, 3> batch{};
        for (size_t c = 0; c < 3; ++c) {
            const size_t i = layout == BatchLayout::kConsecutive ? 3 * b + c : b + c * count;
            batch[c] = i < wavelengths ? i : batch[c > 0 ? c - 1 : 0];
        }
        batches.push_back(batch);
    }
    return batches;
}

uint64_t BatchSeed(uint64_t seed, size_t batch, BatchSeeds seeds) {
    // CLI seeds are below 2^32 (halves: 2s + 2 < 2^34): b * 2^40 keeps them apart.
    return seeds == BatchSeeds::kSame ? seed : seed + (static_cast<uint64_t>(batch) << 40);
}

bool HasSpectralForm(const ModelInfo& info) { return info.capabilities.spectral; }

void RequireSpectralModel(const ModelInfo& info) {
    if (!HasSpectralForm(info)) {
        Fail("model ", info.name,
             " has no per-wavelength form in atmos (its inputs are not an atmosphere's "
             "coefficients); --wavelengths takes the physical models and preetham");
    }
}

SpectralImage RenderSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                             const std::vector<double>& nm, const RenderRequest& request,
                             const PrepareFunction& prepare, SpectralBatching batching) {
    return RenderSpectralRequests(spec, atmosphere, nm, {request}, prepare, nullptr, nullptr,
                                  batching)
        .front();
}

std::vector<SpectralImage> RenderSpectralRequests(
    const ModelSpec& spec, const SpectralAtmosphere& atmosphere, const std::vector<double>& nm,
    const std::vector<RenderRequest>& requests, const PrepareFunction& prepare,
    std::vector<double>* render_seconds, std::vector<MonteCarloReport>* reports,
    SpectralBatching batching) {
    const size_t n = nm.size();
    std::vector<SpectralImage> out(requests.size());
    for (size_t v = 0; v < requests.size(); ++v) {
        out[v].width = requests[v].width;
        out[v].height = requests[v].height;
        out[v].nm = nm;
        out[v].values.assign(static_cast<size_t>(requests[v].width) * requests[v].height * n, 0.0f);
    }
    if (render_seconds) render_seconds->assign(requests.size(), 0.0);
    if (reports) reports->assign(requests.size(), MonteCarloReport());
    if (UsesWideBatches(CreateModel(spec)->Info(), batching)) {
        ForEachWideGroup(
            spec, atmosphere, nm, batching, prepare,
            [&](const std::vector<std::array<size_t, 3>>& indices,
                const std::vector<size_t>& stored, Model& model,
                const std::vector<AtmosphereParameters>&) {
                const size_t channels = 3 * indices.size();
                for (size_t v = 0; v < requests.size(); ++v) {
                    std::vector<float> values;
                    const auto start = std::chrono::steady_clock::now();
                    model.RenderWide(requests[v], &values);
                    if (render_seconds) {
                        (*render_seconds)[v] +=
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                                .count();
                    }
                    const size_t pixels =
                        static_cast<size_t>(requests[v].width) * requests[v].height;
                    for (size_t p = 0; p < pixels; ++p) {
                        for (size_t g = 0; g < indices.size(); ++g) {
                            for (size_t c = 0; c < stored[g]; ++c) {
                                out[v].values[p * n + indices[g][c]] =
                                    values[p * channels + 3 * g + c];
                            }
                        }
                    }
                }
            });
        return out;
    }
    if (std::unique_ptr<Model> model =
            SpectralPathsModel(spec, atmosphere, nm, &requests, prepare)) {
        // Hero-wavelength paths: every wavelength at once, the run's seed.
        std::vector<float> irradiance(n);
        for (size_t v = 0; v < requests.size(); ++v) {
            RenderRequest r = requests[v];
            r.checkpoint.clear();
            r.resume = false;
            r.variance = nullptr;
            for (size_t i = 0; i < n; ++i) {
                irradiance[i] = static_cast<float>(atmosphere.solar_irradiance.At(nm[i]) *
                                                   r.view.sun_irradiance);
            }
            std::vector<float> values;
            const auto start = std::chrono::steady_clock::now();
            model->RenderSpectralPaths(r, &values);
            if (render_seconds) {
                (*render_seconds)[v] +=
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
            if (reports) (*reports)[v].samples = r.monte_carlo.spp;
            for (size_t k = 0; k < values.size(); ++k) {
                out[v].values[k] = values[k] * irradiance[k % n];
            }
        }
        return out;
    }
    ForEachPreparedBatch(
        spec, atmosphere, nm, batching.layout, prepare,
        [&](size_t b, const std::array<size_t, 3>& indices, size_t stored, Model& model,
            const AtmosphereParameters&) {
            for (size_t v = 0; v < requests.size(); ++v) {
                RenderRequest r = requests[v];
                r.checkpoint.clear();
                r.resume = false;
                r.variance = nullptr;
                r.monte_carlo.seed = BatchSeed(r.monte_carlo.seed, b, batching.seeds);
                MonteCarloReport report;
                r.report = &report;
                Image image;
                const auto start = std::chrono::steady_clock::now();
                model.Render(r, &image);
                if (render_seconds) {
                    (*render_seconds)[v] +=
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                            .count();
                }
                if (reports) {
                    MonteCarloReport& total = (*reports)[v];
                    total.samples += report.samples;
                    // The per-pixel noise map stays empty: a batch's map is
                    // of its own wavelengths, not of the colour image.
                    total.noise = std::max(total.noise, report.noise);
                }
                const size_t pixels = static_cast<size_t>(r.width) * r.height;
                for (size_t p = 0; p < pixels; ++p) {
                    for (size_t c = 0; c < stored; ++c) {
                        out[v].values[p * n + indices[c]] = image.data()[p * 3 + c];
                    }
                }
            }
        });
    return out;
}

std::vector<std::vector<size_t>> SpectralRequestGroups(const std::vector<RenderRequest>& requests,
                                                       size_t wavelengths, size_t max_bytes) {
    std::vector<std::vector<size_t>> groups;
    size_t bytes = 0;
    for (size_t i = 0; i < requests.size(); ++i) {
        const size_t b = static_cast<size_t>(requests[i].width) *
                         static_cast<size_t>(requests[i].height) * wavelengths * sizeof(float);
        if (groups.empty() || bytes + b > max_bytes) {
            groups.emplace_back();
            bytes = 0;
        }
        groups.back().push_back(i);
        bytes += b;
    }
    return groups;
}

std::vector<double> SampleSpectral(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                   const std::vector<double>& nm,
                                   const std::vector<SampleQuery>& queries,
                                   const MonteCarloSettings& monte_carlo,
                                   const PrepareFunction& prepare, SpectralBatching batching) {
    const size_t n = nm.size();
    std::vector<double> out(queries.size() * n, 0.0);
    if (UsesWideBatches(CreateModel(spec)->Info(), batching)) {
        ForEachWideGroup(spec, atmosphere, nm, batching, prepare,
                         [&](const std::vector<std::array<size_t, 3>>& indices,
                             const std::vector<size_t>& stored, Model& model,
                             const std::vector<AtmosphereParameters>& batches) {
                             const size_t channels = 3 * indices.size();
                             const std::vector<float> values = model.SampleWide(queries);
                             for (size_t q = 0; q < queries.size(); ++q) {
                                 for (size_t g = 0; g < indices.size(); ++g) {
                                     for (size_t c = 0; c < stored[g]; ++c) {
                                         const int ci = static_cast<int>(c);
                                         out[q * n + indices[g][c]] =
                                             static_cast<double>(values[q * channels + 3 * g + c]) *
                                             batches[g].solar_irradiance[ci];
                                     }
                                 }
                             }
                         });
        return out;
    }
    if (std::unique_ptr<Model> model = SpectralPathsModel(spec, atmosphere, nm, nullptr, prepare)) {
        const std::vector<float> values = model->SampleSpectralPaths(queries, monte_carlo);
        for (size_t k = 0; k < values.size(); ++k) {
            // As the batches: the float radiance times the solar spectrum.
            out[k] = static_cast<double>(values[k]) * atmosphere.solar_irradiance.At(nm[k % n]);
        }
        return out;
    }
    ForEachPreparedBatch(
        spec, atmosphere, nm, batching.layout, prepare,
        [&](size_t b, const std::array<size_t, 3>& indices, size_t stored, Model& model,
            const AtmosphereParameters& batch) {
            MonteCarloSettings mc = monte_carlo;
            mc.seed = BatchSeed(mc.seed, b, batching.seeds);
            const std::vector<SampleAnswer> answers = model.Info().capabilities.stochastic
                                                          ? SampleMonteCarlo(model, queries, mc)
                                                          : model.Sample(queries);
            for (size_t q = 0; q < queries.size(); ++q) {
                for (size_t c = 0; c < stored; ++c) {
                    const int ci = static_cast<int>(c);
                    out[q * n + indices[c]] =
                        static_cast<double>(answers[q].radiance[ci]) * batch.solar_irradiance[ci];
                }
            }
        });
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
    const std::vector<Vec3d> cmf = Cie1931At(image.nm);
    std::vector<double> spectrum(n);
    const size_t pixels = static_cast<size_t>(image.width) * image.height;
    for (size_t p = 0; p < pixels; ++p) {
        for (size_t i = 0; i < n; ++i) spectrum[i] = image.values[p * n + i];
        Vec3d c = SpectrumToXyz(cmf, weights, spectrum.data());
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
    WriteThroughTemporary(path, [&](const std::string& temporary) {
        detail::WriteMultiChannelExr(
            temporary, image.width, image.height, names, values,
            {{"spectralLayoutVersion", "1.0"}, {"emissiveUnits", "W.m^-2.sr^-1"}});
    });
}

}  // namespace atmos
