// atmos: shards of a Monte Carlo render and their merge (see shards.h).
#include "render/shards.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include "atmos/error.h"
#include "base/framed_file.h"
#include "io/bounded_read.h"
#include "metrics/flip.h"
#include "render/progressive.h"

namespace atmos {

namespace {

constexpr char kShardMagic[8] = {'a', 't', 'm', 'o', 's', 's', 'h', '1'};
constexpr const char* kShardFormat = "atmos-shard-1";

void AppendImage(std::string* bytes, const Image& image) {
    bytes->append(reinterpret_cast<const char*>(image.data()), image.size() * sizeof(float));
}

// Pass p's paths per pixel in a render of spp paths in passes of pass_spp.
int64_t PassSamples(int64_t p, int64_t spp, int64_t pass_spp) {
    return std::min(pass_spp, spp - p * pass_spp);
}

std::string ShardName(const MonteCarloShard& s) {
    return std::to_string(s.index + 1) + "/" + std::to_string(s.count);
}

thread_local MonteCarloShard* t_shard = nullptr;

}  // namespace

ShardScope::ShardScope(MonteCarloShard* shard) : previous_(t_shard) { t_shard = shard; }
ShardScope::~ShardScope() { t_shard = previous_; }
MonteCarloShard* CurrentShard() { return t_shard; }

std::vector<int64_t> ShardPasses(int64_t passes, int64_t index, int64_t count, int64_t first_pass) {
    std::vector<int64_t> list;
    for (int64_t p = first_pass + index; p < passes; p += count) list.push_back(p);
    return list;
}

std::string SerializeShardFile(const ShardFile& file) {
    const MonteCarloShard& s = file.shard;
    nlohmann::json header;
    header["format"] = kShardFormat;
    header["fingerprint"] = nlohmann::json::parse(s.fingerprint);
    header["shard"] = {s.index, s.count};
    header["first_pass"] = s.first_pass;
    header["spp"] = s.spp;
    header["passes"] = s.passes;
    header["width"] = s.width;
    header["height"] = s.height;
    nlohmann::json list = nlohmann::json::array();
    for (const MonteCarloPassImage& p : s.pass_images) list.push_back({p.index, p.samples});
    header["pass_list"] = list;
    if (file.rows_done > 0) {
        header["partial"] = {{"pass", file.partial.index},
                             {"samples", file.partial.samples},
                             {"rows_done", file.rows_done}};
    }
    header["extra"] = nlohmann::json::parse(file.extra);
    const std::string text = header.dump();
    std::string bytes = BeginFrame(kShardMagic, text);
    for (const MonteCarloPassImage& p : s.pass_images) AppendImage(&bytes, p.mean);
    if (file.rows_done > 0) AppendImage(&bytes, file.partial.mean);
    EndFrame(&bytes);
    return bytes;
}

ShardFile ParseShardFile(const std::string& bytes, const std::string& what) {
    auto bad = [&](const std::string& why) {
        Fail(what, " is not a usable atmos shard (", why, ")");
    };
    const size_t fixed = kFrameOverhead;
    const uint64_t header_size =
        CheckFrame(bytes, kShardMagic,
                   {"no shard header: not written by `atmos render --shard`, or truncated",
                    "truncated header", "checksum mismatch: damaged or truncated"},
                   bad);
    ShardFile file;
    MonteCarloShard& s = file.shard;
    int64_t pass_spp = 0;
    std::vector<std::pair<int64_t, int64_t>> list;
    try {
        const nlohmann::json header = nlohmann::json::parse(bytes.substr(16, header_size));
        if (header.at("format") != kShardFormat) bad("format is not " + std::string(kShardFormat));
        const nlohmann::json& fp = header.at("fingerprint");
        s.fingerprint = fp.dump();
        pass_spp = fp.at("pass_spp").get<int64_t>();
        s.spp = header.at("spp").get<int64_t>();
        s.first_pass = header.at("first_pass").get<int64_t>();
        s.index = header.at("shard").at(0).get<int64_t>();
        s.count = header.at("shard").at(1).get<int64_t>();
        s.passes = header.at("passes").get<int64_t>();
        s.width = header.at("width").get<int>();
        s.height = header.at("height").get<int>();
        for (const nlohmann::json& e : header.at("pass_list")) {
            list.emplace_back(e.at(0).get<int64_t>(), e.at(1).get<int64_t>());
        }
        if (header.contains("partial")) {
            const nlohmann::json& partial = header["partial"];
            file.partial.index = partial.at("pass").get<int64_t>();
            file.partial.samples = partial.at("samples").get<int64_t>();
            file.rows_done = partial.at("rows_done").get<int>();
            if (file.rows_done <= 0) bad("its partial pass has no rows");
        }
        file.extra = header.at("extra").dump();
    } catch (const nlohmann::json::exception&) {
        bad("unreadable or incomplete header");
    }
    const int64_t spp = s.spp;
    if (spp < 1 || pass_spp < 1 || s.passes != (spp + pass_spp - 1) / pass_spp) {
        bad("its pass count disagrees with its spp and pass size");
    }
    if (s.first_pass < 0 || s.first_pass >= s.passes) bad("its first pass is out of range");
    if (s.count < 1 || s.index < 0 || s.index >= s.count) bad("its shard number is out of range");
    CheckImageDimensions(s.width, s.height, what);
    // Its passes are the shard's, in order, each with the render's samples.
    const std::vector<int64_t> expected = ShardPasses(s.passes, s.index, s.count, s.first_pass);
    if (list.size() > expected.size()) bad("more passes than its shard holds");
    for (size_t i = 0; i < list.size(); ++i) {
        if (list[i].first != expected[i] ||
            list[i].second != PassSamples(list[i].first, spp, pass_spp)) {
            bad("its pass list is not its shard's");
        }
    }
    if (file.rows_done > 0 &&
        (list.size() == expected.size() || file.partial.index != expected[list.size()] ||
         file.partial.samples != PassSamples(file.partial.index, spp, pass_spp) ||
         file.rows_done >= s.height)) {
        bad("its partial pass is not its shard's next");
    }
    const size_t n = static_cast<size_t>(s.width) * static_cast<size_t>(s.height) * 3;
    const size_t images = list.size() + (file.rows_done > 0 ? 1 : 0);
    if ((bytes.size() - fixed - header_size) / sizeof(float) / std::max<size_t>(n, 1) != images ||
        bytes.size() != fixed + header_size + images * n * sizeof(float)) {
        bad("wrong size for its passes");
    }
    const char* data = bytes.data() + 16 + header_size;
    auto read_image = [&](MonteCarloPassImage* p) {
        p->mean.Resize(s.width, s.height);
        std::memcpy(p->mean.data(), data, n * sizeof(float));
        data += n * sizeof(float);
        for (size_t i = 0; i < n; ++i) {
            const float v = p->mean.data()[i];
            if (!std::isfinite(v) || v < 0.0f) bad("a value is negative or not finite");
        }
    };
    for (const auto& [index, samples] : list) {
        MonteCarloPassImage p;
        p.index = index;
        p.samples = samples;
        read_image(&p);
        s.pass_images.push_back(std::move(p));
    }
    if (file.rows_done > 0) read_image(&file.partial);
    return file;
}

ShardFile ReadShardFile(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status)) Fail("shard '", path, "' does not exist");
    if (!std::filesystem::is_regular_file(status)) {
        Fail("shard '", path, "' is not a regular file");
    }
    std::ifstream f(path, std::ios::binary);
    if (!f) Fail("cannot read shard '", path, "'");
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    return ParseShardFile(bytes, "shard '" + path + "'");
}

void MergeShards(const std::vector<ShardFile>& files, const std::vector<std::string>& names,
                 Image* out, Image* variance, MonteCarloReport* report) {
    if (files.empty()) Fail("merge needs at least one shard");
    auto name = [&](size_t i) { return "'" + names.at(i) + "'"; };
    const MonteCarloShard& first = files[0].shard;
    const nlohmann::json fingerprint = nlohmann::json::parse(first.fingerprint);
    for (size_t i = 0; i < files.size(); ++i) {
        const MonteCarloShard& s = files[i].shard;
        if (files[i].rows_done > 0 ||
            s.pass_images.size() != ShardPasses(s.passes, s.index, s.count, s.first_pass).size()) {
            Fail("shard ", name(i), " (", ShardName(s),
                 ") is unfinished (a checkpoint of a render in progress): finish it with "
                 "`atmos render ... --shard ",
                 ShardName(s), " --resume`");
        }
        const nlohmann::json other = nlohmann::json::parse(s.fingerprint);
        if (other != fingerprint) {
            std::string fields;
            for (const auto& item : fingerprint.items()) {
                if (!other.contains(item.key()) || other[item.key()] != item.value()) {
                    fields += (fields.empty() ? "" : ", ") + item.key();
                }
            }
            for (const auto& item : other.items()) {
                if (!fingerprint.contains(item.key())) {
                    fields += (fields.empty() ? "" : ", ") + item.key();
                }
            }
            Fail("shard ", name(i), " is from another render than ", name(0), " (", fields,
                 " differ): merge only the shards of one render");
        }
    }
    // The render: the largest spp among the shards; a shard of fewer paths
    // (an earlier round) stands for its passes where they are whole passes
    // of it.
    const int64_t pass_spp = fingerprint.at("pass_spp").get<int64_t>();
    int64_t spp = 0;
    for (const ShardFile& f : files) spp = std::max(spp, f.shard.spp);
    const int64_t passes = (spp + pass_spp - 1) / pass_spp;
    for (size_t i = 0; i < files.size(); ++i) {
        for (const MonteCarloPassImage& p : files[i].shard.pass_images) {
            if (p.samples != PassSamples(p.index, spp, pass_spp)) {
                Fail("pass ", p.index + 1, " in ", name(i), " holds ", p.samples,
                     " paths per pixel (its render: --spp ", files[i].shard.spp, ") but ",
                     PassSamples(p.index, spp, pass_spp), " in the render of --spp ", spp,
                     " it is merged into: an earlier round merges into a later one only when its "
                     "--spp is a multiple of --pass-spp");
            }
        }
    }
    // Every pass exactly once.
    std::vector<const MonteCarloPassImage*> by_pass(static_cast<size_t>(passes), nullptr);
    std::vector<size_t> owner(static_cast<size_t>(passes), 0);
    for (size_t i = 0; i < files.size(); ++i) {
        for (const MonteCarloPassImage& p : files[i].shard.pass_images) {
            const size_t k = static_cast<size_t>(p.index);
            if (by_pass[k] != nullptr) {
                Fail("pass ", p.index + 1, " of ", passes, " is in both ", name(owner[k]), " (",
                     ShardName(files[owner[k]].shard), ") and ", name(i), " (",
                     ShardName(files[i].shard), "): a shard given twice, or shards that overlap");
            }
            by_pass[k] = &p;
            owner[k] = i;
        }
    }
    std::string missing;
    int64_t missing_count = 0;
    for (int64_t p = 0; p < passes; ++p) {
        if (by_pass[static_cast<size_t>(p)] != nullptr) continue;
        if (++missing_count <= 8) missing += (missing.empty() ? "" : ", ") + std::to_string(p + 1);
    }
    if (missing_count > 0) {
        // The shards of the first file's split that hold none of the given passes.
        bool one_split = first.first_pass == 0;
        for (const ShardFile& f : files) {
            one_split &=
                f.shard.count == first.count && f.shard.first_pass == 0 && f.shard.spp == first.spp;
        }
        std::string shards;
        for (int64_t k = 0; one_split && k < first.count && k < passes; ++k) {
            if (by_pass[static_cast<size_t>(k)] == nullptr) {
                shards += (shards.empty() ? "" : ", ") + std::to_string(k + 1) + "/" +
                          std::to_string(first.count);
            }
        }
        Fail(missing_count, " of ", passes, " passes are missing (pass ", missing,
             missing_count > 8 ? ", ..." : "", shards.empty() ? "" : "; shard " + shards,
             " not given): merge needs every shard of the render");
    }
    // The sums in pass order, as the one-process render adds them.
    const int width = first.width, height = first.height;
    Image sum(width, height), sum_sq(width, height);
    // The even passes' sum too (apart: it does not touch the sums), for the
    // noise between the halves.
    Image sum_even(width, height), ignored(width, height);
    int64_t samples = 0, even_samples = 0;
    for (int64_t p = 0; p < passes; ++p) {
        const MonteCarloPassImage& pass = *by_pass[static_cast<size_t>(p)];
        AccumulatePass(sum.data(), sum_sq.data(), nullptr, pass.mean.data(), sum.size(),
                       static_cast<float>(pass.samples));
        if (p % 2 == 0) {
            AccumulatePass(sum_even.data(), ignored.data(), nullptr, pass.mean.data(), sum.size(),
                           static_cast<float>(pass.samples));
            even_samples += pass.samples;
        }
        samples += pass.samples;
    }
    out->Resize(width, height);
    FinishMonteCarlo(sum, sum_sq, samples, passes, out, variance);
    if (report) {
        report->samples = samples;
        report->noise = -1.0;
        report->noise_map.clear();
        if (passes >= 2) {
            // The HDR-FLIP between the means of the even and the odd passes,
            // the measure of `render --noise` (informational here).
            Image a(width, height), b(width, height);
            const float inv_even = 1.0f / static_cast<float>(even_samples);
            const float inv_odd = 1.0f / static_cast<float>(samples - even_samples);
            for (size_t i = 0; i < sum.size(); ++i) {
                a.data()[i] = sum_even.data()[i] * inv_even;
                b.data()[i] = std::max(sum.data()[i] - sum_even.data()[i], 0.0f) * inv_odd;
            }
            FlipResult halves = HdrFlip(a, b);
            report->noise = halves.mean;
            report->noise_map = std::move(halves.map);
        }
    }
}

}  // namespace atmos
