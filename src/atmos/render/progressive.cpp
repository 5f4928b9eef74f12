// atmos: the progressive renderer of Monte Carlo models (see progressive.h).
#include "render/progressive.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "atmos/error.h"
#include "base/framed_file.h"
#include "base/interrupt.h"
#include "base/progress.h"
#include "io/output_path.h"
#include "metrics/flip.h"
#include "render/render.h"
#include "render/shards.h"

namespace atmos {

namespace {

// The most paths per pixel (and per pass): 2^32, far beyond any render, and
// far from where the pass arithmetic overflows.
constexpr int64_t kMaxMonteCarloSpp = int64_t{1} << 32;

void RequireMonteCarlo(const Model& model) {
    if (!model.Info().capabilities.stochastic) {
        Fail("model ", model.Info().name,
             " is not a Monte Carlo model: --spp, --seed and --pass-spp do not apply to it");
    }
}

void CheckSettings(const MonteCarloSettings& mc) {
    // Bounded so that the pass arithmetic cannot overflow (a --spp near 2^63
    // rendered nothing in 0 s and exited 0).
    if (mc.spp < 1) Fail("Monte Carlo render: spp must be at least 1, got ", mc.spp);
    if (mc.spp > kMaxMonteCarloSpp) {
        Fail("Monte Carlo render: spp must be at most ", kMaxMonteCarloSpp, ", got ", mc.spp);
    }
    if (mc.pass_spp < 0) Fail("Monte Carlo render: pass spp must be >= 0, got ", mc.pass_spp);
    if (mc.pass_spp > kMaxMonteCarloSpp) {
        Fail("Monte Carlo render: pass spp must be at most ", kMaxMonteCarloSpp, ", got ",
             mc.pass_spp);
    }
    if (!(mc.noise_target >= 0.0) || mc.noise_target >= 1.0) {
        Fail("Monte Carlo render: the noise target must be in (0, 1) (0: off), got ",
             mc.noise_target);
    }
    if (!(mc.checkpoint_seconds >= 0.0) || !std::isfinite(mc.checkpoint_seconds)) {
        Fail(
            "Monte Carlo render: the checkpoint interval must be a finite number of seconds >= "
            "0, got ",
            mc.checkpoint_seconds);
    }
}

// Everything that determines a render's passes; a checkpoint resumes only the
// same render.
nlohmann::json CheckpointKey(const Model& model, const RenderRequest& request, int64_t pass_spp) {
    nlohmann::json key;
    key["format"] = "atmos-checkpoint-2";
    // The driver's estimator (passes weighted by their counts, batch-means
    // variance): bump when it changes what a pass adds to the sums.
    key["estimator_version"] = 1;
    key["model"] = model.Info().name;
    key["model_key"] = nlohmann::json::parse(model.PassKey());
    key["view"] = request.view.name;
    key["camera"] = {request.view.camera.position.x,    request.view.camera.position.y,
                     request.view.camera.position.z,    request.view.camera.forward.x,
                     request.view.camera.forward.y,     request.view.camera.forward.z,
                     request.view.camera.tan_half_fov_y};
    if (request.view.camera.projection != Projection::kPerspective ||
        request.view.name == "custom") {
        // A free camera (--camera): its roll and projection too (the named
        // views' keys stay as they were).
        const Camera& c = request.view.camera;
        key["camera_frame"] = {c.right.x,
                               c.right.y,
                               c.right.z,
                               c.up.x,
                               c.up.y,
                               c.up.z,
                               static_cast<double>(c.projection),
                               c.half_fov};
    }
    key["sun"] = {request.view.sun_direction.x, request.view.sun_direction.y,
                  request.view.sun_direction.z};
    key["irradiance"] = request.view.sun_irradiance;
    key["width"] = request.width;
    key["height"] = request.height;
    key["quantity"] = QuantityName(request.quantity);
    key["sun_disc"] = request.sun_disc;
    key["seed"] = request.monte_carlo.seed;
    key["pass_spp"] = pass_spp;
    // A noise-targeted render also keeps the even passes' sum (its halves).
    if (request.monte_carlo.noise_target > 0.0) key["halves"] = true;
    return key;
}

// A shard's fingerprint: what fixes the render's passes (the checkpoint key's
// fields), the same for each of its shards and rounds; the paths per pixel
// are the shard's own field (an earlier round's shards merge into a later
// round's render, render/shards.h).
nlohmann::json ShardFingerprint(const Model& model, const RenderRequest& request,
                                int64_t pass_spp) {
    nlohmann::json key = CheckpointKey(model, request, pass_spp);
    key["format"] = "atmos-shard-1";
    key["wavelengths"] = "rgb";  // the atmosphere's three channels (no spectral shards)
    return key;
}

// Reads the checkpoint of a shard in progress (a shard file with its pass in
// progress) and checks that it is this shard's.
ShardFile ReadShardCheckpoint(const std::string& path, const ShardFile& expected) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(std::filesystem::status(path, ec))) {
        Fail("checkpoint '", path,
             "' is not a regular file (a directory, FIFO, device or socket); remove it or give "
             "another --checkpoint");
    }
    std::ifstream f(path, std::ios::binary);
    if (!f) Fail("cannot read checkpoint '", path, "'");
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    ShardFile file = ParseShardFile(bytes, "checkpoint '" + path + "'");
    if (nlohmann::json::parse(file.shard.fingerprint) !=
            nlohmann::json::parse(expected.shard.fingerprint) ||
        file.shard.index != expected.shard.index || file.shard.count != expected.shard.count ||
        file.shard.spp != expected.shard.spp ||
        file.shard.first_pass != expected.shard.first_pass) {
        Fail("checkpoint '", path,
             "' was made for a different render or shard (model, view, size, seed, spp, "
             "atmosphere, pass size, options or --shard differ); remove it or drop --resume");
    }
    return file;
}

// A checkpoint is one file, STEM.bin, committed atomically: written to a
// temporary created exclusively beside it (.STEM.bin.tmp-RANDOM), fsync'ed, renamed over STEM.bin,
// its directory fsync'ed. A kill at any point leaves the previous checkpoint (or none) intact.
// Layout (host byte order): the 8 bytes "atmosck2", the header's length (uint64), the header (JSON:
// the render's key, width, height, passes_done, samples_done, and for a checkpoint inside a pass
// rows_done and pass_samples: that pass's rows [0, rows_done) of pass_samples samples are in the
// sums too), the sums and the sums of squares (float32, width x height x 3 each; a noise-targeted
// render also the even passes' sum), and a 64-bit FNV-1a checksum of
// everything before it.
constexpr char kCheckpointMagic[8] = {'a', 't', 'm', 'o', 's', 'c', 'k', '2'};

struct CheckpointState {
    int64_t passes_done = 0;
    int64_t samples_done = 0;
    // Inside pass passes_done: its rows [0, rows_done), of pass_samples samples
    // each, are in the sums (0, 0: between passes).
    int rows_done = 0;
    int64_t pass_samples = 0;
    Image sum, sum_sq;
    Image sum_even;  // the even passes' sum (noise-targeted renders only; else empty)
};

void WriteAll(int fd, const std::string& bytes, const std::string& path) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            const int err = errno;
            ::close(fd);
            Fail("cannot write checkpoint '", path, "': ", std::strerror(err));
        }
        done += static_cast<size_t>(w);
    }
}

void CommitCheckpoint(const std::string& path, const std::string& bytes);

void WriteCheckpoint(const std::string& path, const nlohmann::json& key,
                     const CheckpointState& state) {
    nlohmann::json header;
    header["key"] = key;
    header["width"] = state.sum.width();
    header["height"] = state.sum.height();
    header["passes_done"] = state.passes_done;
    header["samples_done"] = state.samples_done;
    header["rows_done"] = state.rows_done;
    header["pass_samples"] = state.pass_samples;
    header["even_sum"] = state.sum_even.size() > 0;
    const std::string text = header.dump();
    const size_t image_bytes = state.sum.size() * sizeof(float);
    std::string bytes = BeginFrame(kCheckpointMagic, text, 3 * image_bytes);
    bytes.append(reinterpret_cast<const char*>(state.sum.data()), image_bytes);
    bytes.append(reinterpret_cast<const char*>(state.sum_sq.data()), image_bytes);
    if (state.sum_even.size() > 0) {
        bytes.append(reinterpret_cast<const char*>(state.sum_even.data()), image_bytes);
    }
    EndFrame(&bytes);
    CommitCheckpoint(path, bytes);
}

// `bytes` to the checkpoint `path`: a temporary, fsync, rename, the directory's fsync.
void CommitCheckpoint(const std::string& path, const std::string& bytes) {
    // The checkpoint's directory is the user's (checked before the work:
    // atmos creates none); the temporary is created exclusively beside it, so
    // a link planted under a predictable name cannot redirect the write.
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    std::string tmp;
    const int fd = CreateExclusiveFile(parent.empty() ? "." : parent.string(),
                                       std::filesystem::path(path).filename().string(), &tmp,
                                       "checkpoint '" + path + "'");
    try {
        WriteAll(fd, bytes, path);
    } catch (...) {
        ::unlink(tmp.c_str());
        throw;
    }
    const bool synced = ::fsync(fd) == 0;
    int sync_error = errno;
    const bool closed = ::close(fd) == 0;  // closed whether or not the fsync failed
    if (synced && !closed) sync_error = errno;
    if (!synced || !closed) {
        ::unlink(tmp.c_str());
        Fail("cannot write checkpoint '", path, "': ", std::strerror(sync_error));
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        Fail("cannot commit checkpoint '", path, "': ", std::strerror(err));
    }
    const std::string dir = parent.empty() ? "." : parent.string();
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

// Reads and verifies a checkpoint of the render `key` (passes of pass_spp,
// spp in all): one atmos::Error for anything that does not add up.
CheckpointState ReadCheckpoint(const std::string& path, const nlohmann::json& key, int width,
                               int height, int64_t spp, int64_t pass_spp, bool halves) {
    auto damaged = [&](const std::string& why) {
        Fail("checkpoint '", path, "' is damaged (", why,
             "); remove it or drop --resume to start over");
    };
    // Only a regular file (a FIFO would block, a device never end), of at
    // most the size this render's checkpoint can have: read before anything
    // is allocated for it.
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(status)) {
        Fail("checkpoint '", path, "' is a directory; remove it or give another --checkpoint");
    }
    if (!std::filesystem::is_regular_file(status)) {
        Fail("checkpoint '", path,
             "' is not a regular file (a FIFO, a device or a socket); remove it or give another "
             "--checkpoint");
    }
    const uintmax_t file_size = std::filesystem::file_size(path, ec);
    const uintmax_t most =
        16 + (uintmax_t{1} << 20) + 8 +
        uintmax_t{3} * static_cast<uintmax_t>(width) * height * 3 * sizeof(float);
    if (ec || file_size > most) damaged("larger than this render's checkpoint can be");
    std::ifstream f(path, std::ios::binary);
    if (!f) Fail("cannot read checkpoint '", path, "'");
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const size_t fixed = kFrameOverhead;
    const uint64_t header_size = CheckFrame(
        bytes, kCheckpointMagic,
        {"not an atmos checkpoint, or truncated", "truncated header", "checksum mismatch"},
        damaged);
    nlohmann::json header;
    try {
        header = nlohmann::json::parse(bytes.substr(16, header_size));
    } catch (const std::exception&) {
        damaged("unreadable header");
    }
    if (!header.contains("key") || header["key"] != key) {
        Fail("checkpoint '", path,
             "' was made for a different render (model, view, size, seed, atmosphere, pass size "
             "or options differ); remove it or drop --resume");
    }
    CheckpointState s;
    try {
        if (header.at("width").get<int>() != width || header.at("height").get<int>() != height) {
            damaged("its size is not the render's");
        }
        s.passes_done = header.at("passes_done").get<int64_t>();
        s.samples_done = header.at("samples_done").get<int64_t>();
        s.rows_done = header.value("rows_done", 0);
        s.pass_samples = header.value("pass_samples", int64_t{0});
    } catch (const nlohmann::json::exception&) {
        damaged("header fields missing");
    }
    const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height) * 3;
    const size_t images = halves ? 3 : 2;
    if (header.value("even_sum", false) != halves) damaged("its halves do not match the render");
    if (bytes.size() != fixed + header_size + images * n * sizeof(float)) damaged("wrong size");
    // Every pass but a last one holds pass_spp samples.
    const bool counts_ok = s.passes_done >= 0 && s.samples_done >= 0 &&
                           s.samples_done <= s.passes_done * pass_spp &&
                           (s.passes_done == 0 || s.samples_done > (s.passes_done - 1) * pass_spp);
    if (!counts_ok) damaged("its pass and sample counts disagree");
    // Inside a pass: a band of rows of a pass of 1 to pass_spp samples.
    const bool band_ok = s.rows_done == 0 ? s.pass_samples == 0
                                          : s.rows_done < height && s.rows_done > 0 &&
                                                s.pass_samples >= 1 && s.pass_samples <= pass_spp;
    if (!band_ok) damaged("its row and pass counts disagree");
    if (s.samples_done + s.pass_samples > spp) {
        Fail("checkpoint '", path, "' already holds ", s.samples_done + s.pass_samples,
             " samples per pixel, more than --spp ", spp);
    }
    s.sum.Resize(width, height);
    s.sum_sq.Resize(width, height);
    std::memcpy(s.sum.data(), bytes.data() + 16 + header_size, n * sizeof(float));
    std::memcpy(s.sum_sq.data(), bytes.data() + 16 + header_size + n * sizeof(float),
                n * sizeof(float));
    if (halves) {
        s.sum_even.Resize(width, height);
        std::memcpy(s.sum_even.data(), bytes.data() + 16 + header_size + 2 * n * sizeof(float),
                    n * sizeof(float));
    }
    for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.sum.data()[i]) || !std::isfinite(s.sum_sq.data()[i]) ||
            (halves && !std::isfinite(s.sum_even.data()[i]))) {
            damaged("a sum is not finite");
        }
    }
    // The sums are of non-negative pass means v weighted by their sample
    // counts w: sum = S w v >= 0, sum_sq = S w v^2 >= 0, the even passes' sum
    // within [0, sum], and (Cauchy-Schwarz) sum^2 <= W sum_sq with W = S w the
    // pixel's samples (zero sums where W is 0). A little slack for float sums.
    for (int y = 0; y < height; ++y) {
        const double samples = static_cast<double>(s.samples_done) +
                               (y < s.rows_done ? static_cast<double>(s.pass_samples) : 0.0);
        for (size_t i = static_cast<size_t>(y) * width * 3;
             i < static_cast<size_t>(y + 1) * width * 3; ++i) {
            const double sum = s.sum.data()[i], sq = s.sum_sq.data()[i];
            const double even = halves ? static_cast<double>(s.sum_even.data()[i]) : 0.0;
            if (sum < 0.0 || sq < 0.0 || even < 0.0) damaged("a sum is negative");
            if (even > sum * (1.0 + 1e-5) + 1e-30) damaged("its halves' sums disagree");
            if (samples == 0.0 ? (sum != 0.0 || sq != 0.0)
                               : sum * sum > samples * sq * (1.0 + 1e-4) + 1e-30) {
                damaged("its sums and sums of squares disagree with the sample counts");
            }
        }
    }
    return s;
}

}  // namespace

void AccumulatePass(float* sum, float* sum_sq, float* sum_even, const float* v, size_t count,
                    float weight) {
    for (size_t i = 0; i < count; ++i) {
        sum[i] += weight * v[i];
        sum_sq[i] += weight * v[i] * v[i];
        if (sum_even) sum_even[i] += weight * v[i];
    }
}

void FinishMonteCarlo(const Image& sum, const Image& sum_sq, int64_t samples_done,
                      int64_t passes_done, Image* out, Image* variance) {
    // Mean, and the variance of the mean from the pass means (batch means):
    // Var(mean) = (E[v^2] - mean^2) / (passes - 1), weights by sample count.
    const size_t n = sum.size();
    if (variance) variance->Resize(sum.width(), sum.height());
    const float inv = 1.0f / static_cast<float>(std::max<int64_t>(samples_done, 1));
    for (size_t i = 0; i < n; ++i) {
        const float mean = sum.data()[i] * inv;
        out->data()[i] = mean;
        if (variance) {
            const float second = sum_sq.data()[i] * inv;
            const float var = passes_done > 1 ? std::max(second - mean * mean, 0.0f) /
                                                    static_cast<float>(passes_done - 1)
                                              : 0.0f;
            variance->data()[i] = var;
        }
    }
    // The mean (also one read back by --resume) goes through the output guard.
    GuardOutput(out->data(), n);
    if (variance) GuardOutput(variance->data(), n);
}

int64_t PassSpp(const MonteCarloSettings& mc) {
    if (mc.pass_spp > 0) return mc.pass_spp;
    if (mc.noise_target > 0.0) return std::clamp<int64_t>(mc.spp / 2, 1, 16);
    return std::clamp<int64_t>(mc.spp / 8, 1, 64);
}

MonteCarloSettings MakeMonteCarloSettings(int64_t spp, int64_t seed, int64_t pass_spp,
                                          const char* spp_flag, const char* seed_flag,
                                          const char* pass_flag) {
    if (spp < 1) Fail(spp_flag, " must be at least 1, got ", spp);
    if (spp > kMaxMonteCarloSpp) {
        Fail(spp_flag, " must be at most ", kMaxMonteCarloSpp, " (2^32) paths, got ", spp);
    }
    if (seed < 0 || seed > 4294967295ll) {
        Fail(seed_flag, " must be in [0, 4294967295], got ", seed);
    }
    if (pass_spp < 0) Fail(pass_flag, " must be >= 0 (0: spp/8 in [1, 64]), got ", pass_spp);
    if (pass_spp > kMaxMonteCarloSpp) {
        Fail(pass_flag, " must be at most ", kMaxMonteCarloSpp, " (2^32) paths, got ", pass_spp);
    }
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
    MonteCarloShard* const shard = CurrentShard();
    if (shard) {
        if (shard->count < 1 || shard->index < 0 || shard->index >= shard->count) {
            Fail("Monte Carlo render: shard ", shard->index + 1, "/", shard->count,
                 " is out of range (K/N with 1 <= K <= N)");
        }
        if (request.quantity != Quantity::kRadiance) {
            Fail(
                "a shard (--shard) holds passes of a radiance render; a transmittance render "
                "is one deterministic pass");
        }
        if (mc.noise_target > 0.0) {
            Fail(
                "a shard (--shard) holds passes of a render of a fixed --spp; a noise target "
                "(--noise) cannot be split into shards (`atmos merge` reports the noise of the "
                "merged passes; a later round, --extend-from, adds paths)");
        }
    }
    if (request.quantity == Quantity::kTransmittance) {
        Progress progress(model.Info().name, static_cast<int64_t>(request.width) * request.height,
                          request.show_progress);
        MonteCarloPass pass;
        pass.seed = mc.seed;
        pass.samples = mc.spp;
        model.RenderPass(request, pass, out, &progress);
        if (request.variance) request.variance->Resize(request.width, request.height);
        if (request.on_pass) request.on_pass(1, 1);
        return;
    }
    // Passes of pass_spp samples (auto: 8 passes, so the variance of the mean
    // can be estimated from the pass means).
    const int64_t spp = mc.spp;
    const int64_t pass_spp = PassSpp(mc);
    const bool noise_mode = mc.noise_target > 0.0;
    // A noise target: whole pairs of passes (even, odd: the two halves).
    int64_t passes = (spp + pass_spp - 1) / pass_spp;
    if (noise_mode) passes = std::max<int64_t>(2, passes + (passes & 1));
    out->Resize(request.width, request.height);
    const size_t n = out->size();
    if (shard && (shard->first_pass < 0 || shard->first_pass >= passes)) {
        Fail("Monte Carlo render: a later round's first pass ", shard->first_pass + 1,
             " is outside the render's ", passes, " passes");
    }
    // The passes this run renders, in order: all of them, or a shard's.
    const std::vector<int64_t> order =
        shard ? ShardPasses(passes, shard->index, shard->count, shard->first_pass)
              : ShardPasses(passes, 0, 1);
    const int64_t run_passes = static_cast<int64_t>(order.size());
    // Its paths per pixel (a shard's own in the messages; noise targets
    // are not split).
    int64_t run_spp = shard ? 0 : spp;
    for (size_t k = 0; shard && k < order.size(); ++k) {
        run_spp += std::min(pass_spp, spp - order[k] * pass_spp);
    }
    // A shard keeps each pass's mean (render/shards.h) instead of the sums.
    ShardFile shard_file;
    if (shard) {
        shard_file.shard.index = shard->index;
        shard_file.shard.count = shard->count;
        shard_file.shard.fingerprint = ShardFingerprint(model, request, pass_spp).dump();
        shard_file.shard.passes = passes;
        shard_file.shard.spp = spp;
        shard_file.shard.first_pass = shard->first_pass;
        shard_file.shard.width = request.width;
        shard_file.shard.height = request.height;
    }

    const std::string stem = request.checkpoint;
    const std::string path = stem + ".bin";
    const nlohmann::json key =
        stem.empty() || shard ? nlohmann::json() : CheckpointKey(model, request, pass_spp);
    // One run per checkpoint: a second run on it fails here, before any pass.
    const FileLock lock(stem.empty() ? std::string() : path);
    // Its place holds a checkpoint or nothing: a directory, a FIFO or a device
    // there is refused before the work, never replaced.
    if (!stem.empty() && !request.resume) CheckCheckpointFile(path);
    CheckpointState state;
    state.sum.Resize(request.width, request.height);
    state.sum_sq.Resize(request.width, request.height);
    if (noise_mode) state.sum_even.Resize(request.width, request.height);
    if (!stem.empty() && request.resume && shard) {
        if (std::filesystem::exists(path)) {
            shard_file = ReadShardCheckpoint(path, shard_file);
            state.passes_done = static_cast<int64_t>(shard_file.shard.pass_images.size());
            for (const MonteCarloPassImage& done : shard_file.shard.pass_images) {
                state.samples_done += done.samples;
            }
            state.rows_done = shard_file.rows_done;
            state.pass_samples = shard_file.rows_done > 0 ? shard_file.partial.samples : 0;
        }
    } else if (!stem.empty() && request.resume) {
        if (std::filesystem::exists(path)) {
            state = ReadCheckpoint(path, key, request.width, request.height,
                                   noise_mode ? passes * pass_spp : spp, pass_spp, noise_mode);
        } else if (std::filesystem::exists(stem + ".json")) {
            Fail("checkpoint '", stem,
                 ".json' is in an older atmos format (sums in EXR files); remove it or drop "
                 "--resume");
        }
    }
    Image& sum = state.sum;
    Image& sum_sq = state.sum_sq;
    int64_t& passes_done = state.passes_done;
    int64_t& samples_done = state.samples_done;
    auto save_checkpoint = [&]() {
        if (stem.empty()) return;
        if (shard) {
            shard_file.rows_done = state.rows_done;
            CommitCheckpoint(path, SerializeShardFile(shard_file));
        } else {
            WriteCheckpoint(path, key, state);
        }
    };

    const int64_t pixels = static_cast<int64_t>(request.width) * request.height;
    Progress progress(model.Info().name,
                      pixels * std::max<int64_t>(run_passes - passes_done, 1) -
                          static_cast<int64_t>(state.rows_done) * request.width,
                      request.show_progress);
    const StopSignalScope stop(!stem.empty());
    // A noise target: the halves' FLIP after pairs of passes, at sample counts
    // growing geometrically (or as FLIP ~ spp^-0.45 predicts, at most x3).
    double noise = -1.0;
    std::vector<float> noise_map;  // its per-pixel map (MonteCarloReport::noise_map)
    int64_t next_check = 0;
    auto measure_noise = [&]() {
        const int64_t half = samples_done / 2;  // even and odd halves hold the same count
        Image a(request.width, request.height), b(request.width, request.height);
        const float inv_half = 1.0f / static_cast<float>(std::max<int64_t>(half, 1));
        for (size_t i = 0; i < n; ++i) {
            a.data()[i] = state.sum_even.data()[i] * inv_half;
            b.data()[i] = (sum.data()[i] - state.sum_even.data()[i]) * inv_half;
        }
        FlipResult halves = HdrFlip(a, b);
        noise = halves.mean;
        noise_map = std::move(halves.map);
        if (request.show_progress) {
            std::fprintf(stderr, "%s: %lld paths per pixel, noise %.4f (target %.4f)\n",
                         model.Info().name.c_str(), static_cast<long long>(samples_done), noise,
                         mc.noise_target);
        }
        const double predicted =
            noise > 0.0 ? samples_done * std::pow(noise / mc.noise_target, 1.0 / 0.45) : 0.0;
        next_check = static_cast<int64_t>(
            std::clamp(1.05 * predicted, 1.3 * samples_done, 3.0 * samples_done));
        return noise <= mc.noise_target;
    };
    bool reached = false;
    // A resumed noise-targeted render between two pairs of passes.
    if (noise_mode && passes_done >= 2 && passes_done % 2 == 0 && state.rows_done == 0) {
        reached = measure_noise();
    }
    // Each pass is rendered in bands of rows (issue 18 item 10) so that a
    // checkpoint, at most every checkpoint_seconds, and a stop on SIGINT or
    // SIGTERM can fall inside a pass: bands of about a second (the measured
    // rate; one row when checkpoint_seconds is 0), the whole image when
    // nothing is checkpointed. Pixels depend on their coordinates only, so the
    // bands do not change the image.
    using Clock = std::chrono::steady_clock;
    const double band_seconds = std::min(1.0, mc.checkpoint_seconds / 2.0);
    const int width = request.width;
    const int height = request.height;
    int band_rows = stem.empty()          ? height
                    : band_seconds <= 0.0 ? 1
                                          : std::clamp(16384 / std::max(width, 1), 1, height);
    auto last_save = Clock::now();
    Image band_image;
    for (int64_t k = passes_done; k < run_passes && !reached; ++k) {
        const int64_t p = order[static_cast<size_t>(k)];
        MonteCarloPass pass;
        pass.seed = mc.seed;
        pass.first_sample = p * pass_spp;
        pass.samples = state.rows_done > 0 ? state.pass_samples  // a resumed pass
                       : noise_mode        ? pass_spp
                                           : std::min(pass_spp, spp - pass.first_sample);
        // Weighted by the pass's sample count so a short last pass counts right.
        const float wgt = static_cast<float>(pass.samples);
        if (shard) {
            shard_file.partial.index = p;
            shard_file.partial.samples = pass.samples;
            // A new pass (else the resumed pass's rows done are kept).
            if (state.rows_done == 0) shard_file.partial.mean.Resize(width, height);
        }
        int signal_number = 0;
        for (int row = state.rows_done; row < height;) {
            pass.row_begin = row;
            pass.rows = std::min(band_rows, height - row);
            const auto band_start = Clock::now();
            model.RenderPass(request, pass, &band_image, &progress);
            if (band_image.width() != width || band_image.height() != pass.rows) {
                Fail("model ", model.Info().name, " rendered ", band_image.width(), "x",
                     band_image.height(), " pixels for a band of ", width, "x", pass.rows,
                     " (Model::RenderPass renders the pass's band of rows)");
            }
            const size_t first = static_cast<size_t>(row) * static_cast<size_t>(width) * 3;
            const size_t count = static_cast<size_t>(pass.rows) * static_cast<size_t>(width) * 3;
            if (shard) {
                std::copy(band_image.data(), band_image.data() + count,
                          shard_file.partial.mean.data() + first);
            } else {
                AccumulatePass(sum.data() + first, sum_sq.data() + first,
                               noise_mode && p % 2 == 0 ? state.sum_even.data() + first : nullptr,
                               band_image.data(), count, wgt);
            }
            row += pass.rows;
            const auto now = Clock::now();
            if (!stem.empty()) {
                const double took = std::chrono::duration<double>(now - band_start).count();
                const double per_row = took / pass.rows;
                band_rows = per_row > 0.0
                                ? static_cast<int>(std::clamp(band_seconds / per_row, 1.0,
                                                              static_cast<double>(height)))
                                : height;
            }
            if (row == height) break;  // the pass's end: below
            state.rows_done = row;
            state.pass_samples = pass.samples;
            signal_number = stop.Received();
            if (signal_number != 0 ||
                std::chrono::duration<double>(now - last_save).count() >= mc.checkpoint_seconds) {
                save_checkpoint();
                last_save = Clock::now();
            }
            if (signal_number != 0) {
                Fail("interrupted by ", StopSignalName(signal_number), " in pass ", k + 1, " of ",
                     run_passes, " (", samples_done, " of ", run_spp, " samples per pixel and ",
                     row, " of ", height, " rows of the next pass done); the checkpoint '", path,
                     "' holds them: the same command with --resume continues");
            }
        }
        state.rows_done = 0;
        state.pass_samples = 0;
        if (shard) {
            MonteCarloPassImage done;
            done.index = p;
            done.samples = pass.samples;
            done.mean = shard_file.partial.mean;
            shard_file.shard.pass_images.push_back(std::move(done));
        }
        ++passes_done;
        samples_done += pass.samples;
        const bool pair_done = !noise_mode || p % 2 == 1;
        if (noise_mode && pair_done && (samples_done >= next_check || k + 1 == run_passes)) {
            reached = measure_noise();
        }
        const auto now = Clock::now();
        signal_number = stop.Received();
        if (signal_number != 0 || k + 1 == run_passes || reached ||
            std::chrono::duration<double>(now - last_save).count() >= mc.checkpoint_seconds) {
            save_checkpoint();
            last_save = now;
        }
        if (request.on_pass) {
            try {
                request.on_pass(passes_done, run_passes);
            } catch (...) {
                save_checkpoint();  // keep the passes done
                throw;
            }
        }
        if (signal_number != 0 && k + 1 < run_passes && !reached) {
            Fail("interrupted by ", StopSignalName(signal_number), " after pass ", passes_done,
                 " of ", run_passes, " (", samples_done, " of ", run_spp,
                 " samples per pixel); the checkpoint '", path,
                 "' holds them: the same command with --resume continues");
        }
    }
    if (request.report) {
        request.report->samples = samples_done;
        request.report->noise = noise;
        request.report->noise_map = std::move(noise_map);
    }
    if (shard) {
        // The shard's passes, not an image (MergeShards makes it).
        shard_file.partial = MonteCarloPassImage();
        *shard = std::move(shard_file.shard);
        out->Resize(0, 0);
        if (request.variance) request.variance->Resize(0, 0);
        return;
    }
    FinishMonteCarlo(sum, sum_sq, samples_done, passes_done, out, request.variance);
}

}  // namespace atmos
