// EXR output and input of Image (DESIGN.md "Outputs"): mean RGB, a "variance" layer, spp.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <fstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "image/image.h"

namespace mcrt {

namespace {

// Channel names in the order of the 3 floats per pixel; "variance." makes a layer
// (OpenEXR "Technical Introduction", Layers).
const char* const rgb_channels[3] = {"R", "G", "B"};
const char* const variance_channels[3] = {"variance.R", "variance.G", "variance.B"};

// Six slices over the interleaved rgb and variance arrays of an image with `window`.
Imf::FrameBuffer interleaved_frame_buffer(const float* rgb, const float* variance,
                                          const Imath::Box2i& window) {
    const size_t x_stride = 3 * sizeof(float);
    const size_t y_stride = x_stride * size_t(window.max.x - window.min.x + 1);
    Imf::FrameBuffer frame_buffer;
    for (int c = 0; c < 3; ++c) {
        frame_buffer.insert(rgb_channels[c],
                            Imf::Slice::Make(Imf::FLOAT, rgb + c, window, x_stride, y_stride));
        // Fill value 0: a file without the variance layer reads as zero variance.
        frame_buffer.insert(variance_channels[c], Imf::Slice::Make(Imf::FLOAT, variance + c, window,
                                                                   x_stride, y_stride, 1, 1, 0.0));
    }
    return frame_buffer;
}

void write_exr_file(const std::string& temporary, const std::string& path, const Image& image,
                    const std::map<std::string, std::string>& attributes) {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (int c = 0; c < 3; ++c) {
        header.channels().insert(rgb_channels[c], Imf::Channel(Imf::FLOAT));
        header.channels().insert(variance_channels[c], Imf::Channel(Imf::FLOAT));
    }
    for (const auto& [name, value] : attributes) {
        header.insert(name, Imf::StringAttribute(value));
    }
    header.insert("spp", Imf::FloatAttribute(float(image.spp)));

    // We own the stream: ~OutputFile writes the line offset table and swallows its errors,
    // so only the stream's state after it tells whether the file is complete.
    errno = 0;
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    if (!stream) {
        throw RuntimeError(path + ": cannot create a temporary file: " + std::strerror(errno));
    }
    {
        Imf::StdOFStream exr_stream(stream, temporary.c_str());
        Imf::OutputFile file(exr_stream, header);
        file.setFrameBuffer(
            interleaved_frame_buffer(image.rgb.data(), image.variance.data(), header.dataWindow()));
        file.writePixels(image.height);
    }
    stream.close();
    if (stream.fail())
        throw RuntimeError(path + ": write failed: " + std::strerror(errno ? errno : EIO));
}

}  // namespace

void write_exr_to(const std::string& file, const std::string& path, const Image& image,
                  const std::map<std::string, std::string>& attributes) {
    const size_t floats = 3 * size_t(image.width) * size_t(image.height);
    if (image.width <= 0 || image.height <= 0 || image.rgb.size() != floats ||
        image.variance.size() != floats) {
        throw RuntimeError(path + ": image of " + std::to_string(image.width) + "x" +
                           std::to_string(image.height) +
                           " pixels is empty or its arrays have the wrong size");
    }
    try {
        write_exr_file(file, path, image, attributes);
    } catch (const RuntimeError&) {
        throw;
    } catch (const std::exception& e) {
        // OpenEXR throws Iex exceptions (std::exception) for I/O and header errors.
        throw RuntimeError(path + ": cannot write EXR: " + e.what());
    }
}

void write_exr(const std::string& path, const Image& image,
               const std::map<std::string, std::string>& attributes) {
    write_atomically(path, [&](const std::string& temporary) {
        write_exr_to(temporary, path, image, attributes);
    });
}

Image read_exr(const std::string& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        for (const char* name : rgb_channels) {
            if (!header.channels().findChannel(name)) {
                throw InputError(path + ": EXR has no channel " + name);
            }
        }
        const Imath::Box2i& window = header.dataWindow();
        Image image(window.max.x - window.min.x + 1, window.max.y - window.min.y + 1);
        file.setFrameBuffer(
            interleaved_frame_buffer(image.rgb.data(), image.variance.data(), window));
        file.readPixels(window.min.y, window.max.y);
        if (const auto* spp = header.findTypedAttribute<Imf::FloatAttribute>("spp")) {
            image.spp = spp->value();
        }
        return image;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read EXR: " + e.what());
    }
}

}  // namespace mcrt
