// atmos: OpenEXR reading and writing.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgba.h>
#include <ImfRgbaFile.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>

#include <cstdint>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "io/bounded_read.h"
#include "io/image_formats.h"

namespace atmos::detail {

namespace {

// Sizes an image for an EXR data window, rejecting absurd dimensions.
Image AllocateFor(const Imath::Box2i& window, const std::string& path) {
    const std::int64_t width = std::int64_t{window.max.x} - window.min.x + 1;
    const std::int64_t height = std::int64_t{window.max.y} - window.min.y + 1;
    if (width <= 0 || height <= 0) {
        Fail("cannot read '", path, "': invalid EXR data window (", width, "x", height, ")");
    }
    CheckImageDimensions(width, height, "'" + path + "'");  // before allocating
    return Image(static_cast<int>(width), static_cast<int>(height));
}

std::string ChannelNames(const Imf::ChannelList& channels) {
    std::ostringstream os;
    bool first = true;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
        os << (first ? "" : ", ") << it.name();
        first = false;
    }
    return first ? std::string("none") : os.str();
}

// Reads a luminance/chroma (Y, RY, BY) file through the RGBA interface, which
// does the colour conversion.
Image ReadLuminanceChroma(const std::string& path) {
    Imf::RgbaInputFile file(path.c_str());
    const Imath::Box2i window = file.dataWindow();
    Image image = AllocateFor(window, path);
    const int width = image.width();
    const int height = image.height();
    std::vector<Imf::Rgba> pixels(static_cast<size_t>(width) * height);
    // The frame buffer is addressed by absolute pixel coordinates; shift the base
    // by the data window origin in integer arithmetic (as Imf::Slice::Make does).
    const std::int64_t origin = std::int64_t{window.min.x} + std::int64_t{window.min.y} * width;
    const std::intptr_t base =
        reinterpret_cast<std::intptr_t>(pixels.data()) -
        static_cast<std::intptr_t>(origin) * static_cast<std::intptr_t>(sizeof(Imf::Rgba));
    file.setFrameBuffer(reinterpret_cast<Imf::Rgba*>(base), 1, static_cast<size_t>(width));
    file.readPixels(window.min.y, window.max.y);
    float* out = image.data();
    for (const Imf::Rgba& p : pixels) {
        *out++ = static_cast<float>(p.r);
        *out++ = static_cast<float>(p.g);
        *out++ = static_cast<float>(p.b);
    }
    return image;
}

Image ReadExrImpl(const std::string& path) {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imf::ChannelList& channels = header.channels();
    const Imath::Box2i window = header.dataWindow();

    for (auto it = channels.begin(); it != channels.end(); ++it) {
        const std::string name = it.name();
        if ((name == "R" || name == "G" || name == "B" || name == "Y") &&
            (it.channel().xSampling != 1 || it.channel().ySampling != 1)) {
            Fail("cannot read '", path, "': EXR channel '", name,
                 "' is subsampled, which is not supported");
        }
    }

    const bool has_r = channels.findChannel("R") != nullptr;
    const bool has_g = channels.findChannel("G") != nullptr;
    const bool has_b = channels.findChannel("B") != nullptr;
    const bool has_y = channels.findChannel("Y") != nullptr;
    const bool grey = !has_r && !has_g && !has_b && has_y;
    if (grey && channels.findChannel("RY") != nullptr && channels.findChannel("BY") != nullptr) {
        return ReadLuminanceChroma(path);
    }
    if (!grey && !(has_r && has_g && has_b)) {
        std::string missing;
        if (!has_r) missing += " R";
        if (!has_g) missing += " G";
        if (!has_b) missing += " B";
        Fail("cannot read '", path, "': EXR file lacks channel(s)", missing,
             " (need R, G, B or Y; found: ", ChannelNames(channels), ")");
    }

    Image image = AllocateFor(window, path);
    const size_t x_stride = 3 * sizeof(float);
    const size_t y_stride = x_stride * static_cast<size_t>(image.width());
    float* base = image.data();
    Imf::FrameBuffer frame;
    if (grey) {
        frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, base, window, x_stride, y_stride));
    } else {
        frame.insert("R", Imf::Slice::Make(Imf::FLOAT, base + 0, window, x_stride, y_stride));
        frame.insert("G", Imf::Slice::Make(Imf::FLOAT, base + 1, window, x_stride, y_stride));
        frame.insert("B", Imf::Slice::Make(Imf::FLOAT, base + 2, window, x_stride, y_stride));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);

    if (grey) {
        float* p = image.data();
        for (size_t i = 0; i < image.size(); i += 3) p[i + 1] = p[i + 2] = p[i];
    }
    return image;
}

// The file is built in memory and written by WriteFileBytes, whose every
// write and close is checked: OpenEXR's OutputFile writes its last bytes (the
// line offsets) and flushes from its destructor, where a failure (a full
// disk) is swallowed and a truncated file would pass as written.
void WriteExrThroughMemory(const std::string& path, const Imf::Header& header,
                           const Imf::FrameBuffer& frame, int rows) {
    Imf::StdOSStream stream;
    {
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(rows);
    }
    const std::string bytes = stream.str();
    WriteFileBytes(path, std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
}

}  // namespace

void WriteExr(const Image& image, const std::string& path) {
    try {
        Imf::Header header(image.width(), image.height());
        header.compression() = Imf::ZIP_COMPRESSION;
        header.channels().insert("R", Imf::Channel(Imf::FLOAT));
        header.channels().insert("G", Imf::Channel(Imf::FLOAT));
        header.channels().insert("B", Imf::Channel(Imf::FLOAT));

        const Imath::Box2i window = header.dataWindow();
        const size_t x_stride = 3 * sizeof(float);
        const size_t y_stride = x_stride * static_cast<size_t>(image.width());
        const float* base = image.data();
        Imf::FrameBuffer frame;
        frame.insert("R", Imf::Slice::Make(Imf::FLOAT, base + 0, window, x_stride, y_stride));
        frame.insert("G", Imf::Slice::Make(Imf::FLOAT, base + 1, window, x_stride, y_stride));
        frame.insert("B", Imf::Slice::Make(Imf::FLOAT, base + 2, window, x_stride, y_stride));

        WriteExrThroughMemory(path, header, frame, image.height());
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        Fail("cannot write EXR '", path, "': ", e.what());
    }
}

void WriteMultiChannelExr(const std::string& path, int width, int height,
                          const std::vector<std::string>& names, const std::vector<float>& values,
                          const std::vector<std::pair<std::string, std::string>>& attributes) {
    try {
        Imf::Header header(width, height);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const auto& [name, value] : attributes) {
            header.insert(name, Imf::StringAttribute(value));
        }
        for (const std::string& name : names)
            header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        const Imath::Box2i window = header.dataWindow();
        const size_t x_stride = names.size() * sizeof(float);
        const size_t y_stride = x_stride * static_cast<size_t>(width);
        Imf::FrameBuffer frame;
        for (size_t c = 0; c < names.size(); ++c) {
            frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, values.data() + c, window, x_stride,
                                                    y_stride));
        }
        WriteExrThroughMemory(path, header, frame, height);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        Fail("cannot write EXR '", path, "': ", e.what());
    }
}

Image ReadExr(const std::string& path) {
    RequireRegularInput(path, "EXR");  // OpenEXR opens by name: a FIFO would block it
    try {
        return ReadExrImpl(path);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        Fail("cannot read EXR '", path, "': ", e.what());
    }
}

}  // namespace atmos::detail
