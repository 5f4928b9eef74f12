#include "io/table_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <exception>
#include <vector>

#include "atmos/error.h"

namespace atmos {

namespace {
const char* const kChannelNames[4] = {"R", "G", "B", "A"};
}

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
