// atmos: the progressive renderer of Monte Carlo models (see progressive.h).
#include "render/progressive.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "atmos/error.h"
#include "base/progress.h"

namespace atmos {

namespace {

void RequireMonteCarlo(const Model& model) {
    if (!model.Info().capabilities.stochastic) {
        Fail("model ", model.Info().name,
             " is not a Monte Carlo model: --spp, --seed and --pass-spp do not apply to it");
    }
}

void CheckSettings(const MonteCarloSettings& mc) {
    if (mc.spp < 1) Fail("Monte Carlo render: spp must be at least 1, got ", mc.spp);
    if (mc.pass_spp < 0) Fail("Monte Carlo render: pass spp must be >= 0, got ", mc.pass_spp);
}

// Everything that determines a render's passes; a checkpoint resumes only the
// same render.
nlohmann::json CheckpointKey(const Model& model, const RenderRequest& request, int64_t pass_spp) {
    nlohmann::json key;
    key["format"] = "atmos-checkpoint-2";
    key["model"] = model.Info().name;
    key["model_key"] = nlohmann::json::parse(model.PassKey());
    key["view"] = request.view.name;
    key["camera"] = {request.view.camera.position.x,    request.view.camera.position.y,
                     request.view.camera.position.z,    request.view.camera.forward.x,
                     request.view.camera.forward.y,     request.view.camera.forward.z,
                     request.view.camera.tan_half_fov_y};
    key["sun"] = {request.view.sun_direction.x, request.view.sun_direction.y,
                  request.view.sun_direction.z};
    key["irradiance"] = request.view.sun_irradiance;
    key["width"] = request.width;
    key["height"] = request.height;
    key["quantity"] = QuantityName(request.quantity);
    key["sun_disc"] = request.sun_disc;
    key["seed"] = request.monte_carlo.seed;
    key["pass_spp"] = pass_spp;
    return key;
}

}  // namespace

int64_t PassSpp(const MonteCarloSettings& mc) {
    return mc.pass_spp > 0 ? mc.pass_spp : std::clamp<int64_t>(mc.spp / 8, 1, 64);
}

MonteCarloSettings MakeMonteCarloSettings(int64_t spp, int64_t seed, int64_t pass_spp,
                                          const char* spp_flag, const char* seed_flag,
                                          const char* pass_flag) {
    if (spp < 1) Fail(spp_flag, " must be at least 1, got ", spp);
    if (seed < 0 || seed > 4294967295ll) {
        Fail(seed_flag, " must be in [0, 4294967295], got ", seed);
    }
    if (pass_spp < 0) Fail(pass_flag, " must be >= 0 (0: spp/8 in [1, 64]), got ", pass_spp);
    MonteCarloSettings mc;
    mc.spp = spp;
    mc.seed = static_cast<uint64_t>(seed);
    mc.pass_spp = pass_spp;
    return mc;
}

std::vector<SampleAnswer> SampleMonteCarlo(const Model& model,
                                           const std::vector<SampleQuery>& queries,
                                           const MonteCarloSettings& mc) {
    RequireMonteCarlo(model);
    CheckSettings(mc);
    MonteCarloPass pass;
    pass.seed = mc.seed;
    pass.first_sample = 0;
    pass.samples = mc.spp;
    return model.SamplePass(queries, pass);
}

void RenderProgressive(const Model& model, const RenderRequest& request, Image* out) {
    RequireMonteCarlo(model);
    const MonteCarloSettings& mc = request.monte_carlo;
    CheckSettings(mc);
    if (request.quantity == Quantity::kTransmittance) {
        Progress progress(model.Info().name, static_cast<int64_t>(request.width) * request.height,
                          request.show_progress);
        MonteCarloPass pass;
        pass.seed = mc.seed;
        pass.samples = mc.spp;
        model.RenderPass(request, pass, out, &progress);
        if (request.variance) request.variance->Resize(request.width, request.height);
        return;
    }
    // Passes of pass_spp samples (auto: 8 passes, so the variance of the mean
    // can be estimated from the pass means).
    const int64_t spp = mc.spp;
    const int64_t pass_spp = PassSpp(mc);
    const int64_t passes = (spp + pass_spp - 1) / pass_spp;
    out->Resize(request.width, request.height);
    const size_t n = out->size();
    Image sum(request.width, request.height), sum_sq(request.width, request.height);
    int64_t passes_done = 0;
    int64_t samples_done = 0;

    const std::string stem = request.checkpoint;
    const nlohmann::json key =
        stem.empty() ? nlohmann::json() : CheckpointKey(model, request, pass_spp);
    if (!stem.empty() && request.resume && std::filesystem::exists(stem + ".json")) {
        std::ifstream f(stem + ".json");
        nlohmann::json saved;
        try {
            f >> saved;
        } catch (const std::exception& ex) {
            Fail("checkpoint '", stem, ".json' is unreadable: ", ex.what());
        }
        if (!saved.contains("key") || saved["key"] != key) {
            Fail("checkpoint '", stem,
                 ".json' was made for a different render (model, view, size, seed, atmosphere, "
                 "pass size or options differ); remove it or drop --resume");
        }
        passes_done = saved.value("passes_done", int64_t{0});
        samples_done = saved.value("samples_done", int64_t{0});
        if (passes_done > passes || samples_done > spp) {
            Fail("checkpoint '", stem, "' already holds ", samples_done,
                 " samples per pixel, more than --spp ", spp);
        }
        sum = ReadImage(stem + ".sum.exr");
        sum_sq = ReadImage(stem + ".sumsq.exr");
        if (sum.width() != request.width || sum.height() != request.height ||
            sum_sq.width() != request.width || sum_sq.height() != request.height) {
            Fail("checkpoint '", stem, "' images do not match the render size");
        }
    }
    auto save_checkpoint = [&]() {
        if (stem.empty()) return;
        const std::filesystem::path parent = std::filesystem::path(stem).parent_path();
        if (!parent.empty()) std::filesystem::create_directories(parent);
        WriteImage(sum, stem + ".sum.exr");
        WriteImage(sum_sq, stem + ".sumsq.exr");
        nlohmann::json saved;
        saved["key"] = key;
        saved["passes_done"] = passes_done;
        saved["samples_done"] = samples_done;
        const std::string tmp = stem + ".json.tmp";
        {
            std::ofstream f(tmp);
            f << saved.dump(1) << "\n";
            if (!f) Fail("cannot write checkpoint '", tmp, "'");
        }
        std::filesystem::rename(tmp, stem + ".json");
    };

    const int64_t pixels = static_cast<int64_t>(request.width) * request.height;
    Progress progress(model.Info().name, pixels * std::max<int64_t>(passes - passes_done, 1),
                      request.show_progress);
    Image pass_image;
    auto last_save = std::chrono::steady_clock::now();
    for (int64_t p = passes_done; p < passes; ++p) {
        MonteCarloPass pass;
        pass.seed = mc.seed;
        pass.first_sample = p * pass_spp;
        pass.samples = std::min(pass_spp, spp - pass.first_sample);
        model.RenderPass(request, pass, &pass_image, &progress);
        // Weighted by the pass's sample count so a short last pass counts right.
        const float wgt = static_cast<float>(pass.samples);
        for (size_t i = 0; i < n; ++i) {
            const float v = pass_image.data()[i];
            sum.data()[i] += wgt * v;
            sum_sq.data()[i] += wgt * v * v;
        }
        ++passes_done;
        samples_done += pass.samples;
        const auto now = std::chrono::steady_clock::now();
        if (std::chrono::duration<double>(now - last_save).count() > 10.0 || p + 1 == passes) {
            save_checkpoint();
            last_save = now;
        }
    }
    // Mean, and the variance of the mean from the pass means (batch means):
    // Var(mean) = (E[v^2] - mean^2) / (passes - 1), weights by sample count.
    if (request.variance) request.variance->Resize(request.width, request.height);
    const float inv = 1.0f / static_cast<float>(std::max<int64_t>(samples_done, 1));
    for (size_t i = 0; i < n; ++i) {
        const float mean = sum.data()[i] * inv;
        out->data()[i] = mean;
        if (request.variance) {
            const float second = sum_sq.data()[i] * inv;
            const float var = passes_done > 1 ? std::max(second - mean * mean, 0.0f) /
                                                    static_cast<float>(passes_done - 1)
                                              : 0.0f;
            request.variance->data()[i] = var;
        }
    }
}

}  // namespace atmos
