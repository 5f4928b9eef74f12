// atmos: the progressive renderer of Monte Carlo models.
//
// Any model whose ModelCapabilities::stochastic is set renders through here:
// the model provides one pass (Model::RenderPass: the mean of a range of
// samples, from a seed), and the driver runs the passes of
// RenderRequest::monte_carlo, weights them by their sample counts, writes
// checkpoints (one file, STEM.bin: the sums, the sums of squares, the counts and
// a checksum, committed atomically) at most every 10 s and after the last pass,
// resumes from one (verifying sizes, counts, checksum and finiteness: one clear
// error otherwise, never a wrong image), and estimates the variance of the
// mean from the pass means (batch means). Random numbers depend on (seed,
// pixel, sample index) only (base/rng.h), so a render split into passes, or
// interrupted and resumed, is the same image.
#pragma once

#include <cstdint>
#include <vector>

#include "atmos/image.h"
#include "atmos/model.h"

namespace atmos {

// Paths per pass: mc.pass_spp, or (0) spp / 8 clamped to [1, 64] (with a noise
// target: spp / 2 clamped to [1, 16], the passes alternating between the halves).
int64_t PassSpp(const MonteCarloSettings& mc);

// The settings of `--spp`, `--seed` and `--pass-spp` (the flags' names are
// given for the messages): one atmos::Error unless spp >= 1, seed in
// [0, 2^32 - 1] and pass_spp >= 0.
MonteCarloSettings MakeMonteCarloSettings(int64_t spp, int64_t seed, int64_t pass_spp,
                                          const char* spp_flag = "--spp",
                                          const char* seed_flag = "--seed",
                                          const char* pass_flag = "--pass-spp");

// Renders `request` with a Monte Carlo model (throws atmos::Error for a model
// that does not declare itself one). Radiance: passes, checkpoints, resume
// and request.variance as above. Transmittance: one pass of every sample, no
// checkpoint, a zero variance.
void RenderProgressive(const Model& model, const RenderRequest& request, Image* out);

// Answers queries with a Monte Carlo model: one pass of mc.spp paths per query
// from mc.seed (throws for a model that is not Monte Carlo).
std::vector<SampleAnswer> SampleMonteCarlo(const Model& model,
                                           const std::vector<SampleQuery>& queries,
                                           const MonteCarloSettings& mc);

// The host side of a Monte Carlo model: Render and Sample are the driver's
// (Sample with the default MonteCarloSettings); the model implements Info,
// Prepare, RenderPass, SamplePass and PassKey.
class MonteCarloModel : public Model {
  public:
    void Render(const RenderRequest& request, Image* out) const final {
        RenderProgressive(*this, request, out);
    }
    std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const final {
        return SampleMonteCarlo(*this, queries, MonteCarloSettings());
    }
};

}  // namespace atmos
