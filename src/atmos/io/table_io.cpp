#include "io/table_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "atmos/error.h"
#include "io/text_files.h"

namespace atmos {

namespace {
const char* const kChannelNames[4] = {"R", "G", "B", "A"};

namespace fs = std::filesystem;

// The table STEM of the bake in `dir` from its tables.f32 (a viewer's bake
// keeps that blob only, docs/engine.md): the bake's JSON ("raw" -> "tables"
// -> STEM) gives its sizes and offset; the blob's layout (channel fastest, then
// x, y, layer) is Table's.
Table ReadRawFloat32Table(const fs::path& dir, const std::string& stem, int depth, int channels) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        if (e.path().extension() != ".json") continue;
        nlohmann::json j;
        try {
            j = nlohmann::json::parse(ReadWholeFile(e.path()));
        } catch (const std::exception&) {
            continue;
        }
        if (!j.is_object() || !j.contains("raw") || !j["raw"].is_object() ||
            !j["raw"].contains("tables") || !j["raw"]["tables"].contains(stem)) {
            continue;
        }
        const fs::path blob_path = dir / "tables.f32";
        try {
            const nlohmann::json& t = j["raw"]["tables"][stem];
            const int w = t.at("width").get<int>(), h = t.at("height").get<int>();
            const int d = t.at("depth").get<int>(), c = t.at("channels").get<int>();
            const size_t offset = t.at("float32_offset").get<size_t>();
            if (d != depth || c != channels || w < 1 || h < 1) {
                Fail("table '", stem, "' in '", blob_path.string(), "' is ", w, "x", h, "x", d,
                     " with ", c, " channels, not ", depth, " layers of ", channels, " channels");
            }
            const std::string blob = ReadWholeFile(blob_path);
            Table table(w, h, d, c);
            const size_t bytes = table.size() * sizeof(float);
            if (offset > blob.size() || blob.size() - offset < bytes) {
                Fail("'", blob_path.string(), "' is too short for table '", stem, "'");
            }
            std::memcpy(table.data(), blob.data() + offset, bytes);  // little-endian hosts
            return table;
        } catch (const nlohmann::json::exception& ex) {
            Fail("'", e.path().string(), "': raw table '", stem, "': ", ex.what());
        }
    }
    Fail("cannot read table '", (dir / (stem + ".exr")).string(),
         "': no such file, and no bake JSON in that directory describes a raw table '", stem,
         "' in tables.f32");
}
}  // namespace

void WriteTableExr(const Table& table, const std::string& path) {
    const int w = table.width() * table.depth();
    const int h = table.height();
    const int c = table.channels();
    if (w <= 0 || h <= 0 || c < 1 || c > 4) Fail("cannot write empty table '", path, "'");
    // Re-layout: layer z goes to columns [z * width, (z + 1) * width).
    std::vector<float> pixels(static_cast<size_t>(w) * h * c);
    for (int z = 0; z < table.depth(); ++z) {
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < table.width(); ++x) {
                const float* src =
                    table.data() + ((static_cast<size_t>(z) * h + y) * table.width() + x) * c;
                float* dst =
                    pixels.data() + (static_cast<size_t>(y) * w + z * table.width() + x) * c;
                for (int k = 0; k < c; ++k) dst[k] = src[k];
            }
        }
    }
    try {
        Imf::Header header(w, h);
        header.compression() = Imf::ZIP_COMPRESSION;
        Imf::FrameBuffer fb;
        for (int k = 0; k < c; ++k) {
            header.channels().insert(kChannelNames[k], Imf::Channel(Imf::FLOAT));
            fb.insert(kChannelNames[k],
                      Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data() + k),
                                 sizeof(float) * c, sizeof(float) * c * static_cast<size_t>(w)));
        }
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(fb);
        file.writePixels(h);
    } catch (const std::exception& e) {
        Fail("cannot write '", path, "': ", e.what());
    }
}

Table ReadTableExr(const std::string& path, int depth, int channels) {
    const fs::path p(path);
    std::error_code ec;
    if (!fs::exists(p, ec) && fs::exists(p.parent_path() / "tables.f32", ec)) {
        return ReadRawFloat32Table(p.parent_path(), p.stem().string(), depth, channels);
    }
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i dw = file.header().dataWindow();
        const int w = dw.max.x - dw.min.x + 1;
        const int h = dw.max.y - dw.min.y + 1;
        if (depth < 1 || channels < 1 || channels > 4 || w % depth != 0) {
            Fail("table '", path, "' is ", w, "x", h, ", not ", depth, " layers of ", channels,
                 " channels");
        }
        std::vector<float> pixels(static_cast<size_t>(w) * h * channels);
        Imf::FrameBuffer fb;
        for (int k = 0; k < channels; ++k) {
            if (!file.header().channels().findChannel(kChannelNames[k])) {
                Fail("table '", path, "' has no channel ", kChannelNames[k]);
            }
            char* base = reinterpret_cast<char*>(pixels.data() + k) -
                         (static_cast<ptrdiff_t>(dw.min.x) + static_cast<ptrdiff_t>(dw.min.y) * w) *
                             static_cast<ptrdiff_t>(sizeof(float)) * channels;
            fb.insert(kChannelNames[k],
                      Imf::Slice(Imf::FLOAT, base, sizeof(float) * channels,
                                 sizeof(float) * channels * static_cast<size_t>(w)));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        const int width = w / depth;
        Table table(width, h, depth, channels);
        for (int z = 0; z < depth; ++z) {
            for (int y = 0; y < h; ++y) {
                for (int x = 0; x < width; ++x) {
                    const float* src =
                        pixels.data() + (static_cast<size_t>(y) * w + z * width + x) * channels;
                    float* dst = table.Texel(x, y, z);
                    for (int k = 0; k < channels; ++k) dst[k] = src[k];
                }
            }
        }
        return table;
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        Fail("cannot read table '", path, "': ", e.what());
    }
}

}  // namespace atmos
