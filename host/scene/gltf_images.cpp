// Decoding glTF images with stb_image (Debian's libstb, which holds the implementation): the
// encoded bytes located and identified, every header checked against the limits, then the images
// decoded on several threads into Scene::images.
#include "scene/gltf_images.h"

#include <stb/stb_image.h>

#include <algorithm>
#include <climits>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>

#include "image/jpeg_structure.h"
#include "image/png_structure.h"
#include "scene/gltf_limits.h"

namespace mcrt::gltf {

namespace {

enum class Format { Png, Jpeg };

const char* format_name(Format format) { return format == Format::Png ? "PNG" : "JPEG"; }

// One image to decode: where its encoded bytes are, what they are and the size they declare.
struct Encoded {
    std::string element;  // "image 3 (wall.png)", for messages
    const unsigned char* data = nullptr;
    size_t size = 0;
    Format format = Format::Png;
    unsigned width = 0, height = 0;
    PngLayout png;              // a PNG's chunks
    JpegFrame jpeg;             // a JPEG's frame header
    uint64_t decode_bytes = 0;  // what decoding it holds at most (decode_bytes())
};

bool starts_with(const unsigned char* data, size_t size, const char* prefix, size_t length) {
    return size >= length && std::memcmp(data, prefix, length) == 0;
}

// "image 3 (wall.png)": the index, and the uri of a file or the name where there is one.
std::string image_element(const tinygltf::Image& image, size_t index) {
    std::string element = element_name("image", index);
    if (!image.uri.empty()) return element + " (" + image.uri + ")";
    if (!image.name.empty()) return element + " (\"" + image.name + "\")";
    return element;
}

// The encoded bytes of `image`: its bufferView's, once the view is checked to lie inside its
// buffer (tinygltf does not check), or those gltf_parse.cpp kept of its uri.
void locate_bytes(const tinygltf::Model& model, const tinygltf::Image& image, Encoded& encoded,
                  const Diagnostics& diag) {
    if (image.bufferView == -1) {
        if (image.image.empty()) diag.fail(encoded.element, "no bytes could be read from its uri");
        encoded.data = image.image.data();
        encoded.size = image.image.size();
        return;
    }
    const tinygltf::BufferView& view =
        checked_at(model.bufferViews, image.bufferView, "bufferView", encoded.element, diag);
    const std::string view_element = element_name("bufferView", size_t(image.bufferView));
    const tinygltf::Buffer& buffer =
        checked_at(model.buffers, view.buffer, "buffer", view_element, diag);
    if (view.byteOffset > buffer.data.size() ||
        view.byteLength > buffer.data.size() - view.byteOffset) {
        diag.fail(view_element, "bytes " + std::to_string(view.byteOffset) + " + " +
                                    std::to_string(view.byteLength) + " overrun buffer " +
                                    std::to_string(view.buffer) + " (" +
                                    std::to_string(buffer.data.size()) + " bytes)");
    }
    encoded.data = buffer.data.data() + view.byteOffset;
    encoded.size = view.byteLength;
}

// "Images": a glTF image is PNG or JPEG. KTX2, WebP and DDS images come with texture extensions
// mcrt does not implement: named, whether the mimeType or the bytes say so.
void identify_format(const tinygltf::Image& image, Encoded& encoded, const Diagnostics& diag) {
    const unsigned char* d = encoded.data;
    const size_t n = encoded.size;
    const char* extension = nullptr;
    if (image.mimeType == "image/ktx2" || starts_with(d, n, "\xABKTX 20\xBB\r\n\x1A\n", 12)) {
        extension = "KHR_texture_basisu (image/ktx2)";
    } else if (image.mimeType == "image/webp" ||
               (starts_with(d, n, "RIFF", 4) && n >= 12 && std::memcmp(d + 8, "WEBP", 4) == 0)) {
        extension = "EXT_texture_webp (image/webp)";
    } else if (image.mimeType == "image/vnd-ms.dds" || starts_with(d, n, "DDS ", 4)) {
        extension = "MSFT_texture_dds (image/vnd-ms.dds)";
    }
    if (extension) {
        diag.fail(encoded.element, std::string("an image of ") + extension +
                                       ", which mcrt does not implement (PNG and JPEG are read)");
    }
    if (starts_with(d, n, "\x89PNG\r\n\x1A\n", 8)) {
        encoded.format = Format::Png;
    } else if (starts_with(d, n, "\xFF\xD8\xFF", 3)) {
        encoded.format = Format::Jpeg;
    } else {
        diag.fail(encoded.element, "neither PNG nor JPEG (glTF 2.0 \"Images\"): " +
                                       std::to_string(n) + " bytes of another kind");
    }
}

// The declared size: texels on both axes, at most kMaxImageSide per side.
void check_size(const Encoded& encoded, const Diagnostics& diag) {
    if (encoded.width == 0 || encoded.height == 0) {
        diag.fail(encoded.element, std::string("the ") + format_name(encoded.format) +
                                       " declares no texels (a side of 0)");
    }
    if (encoded.width > kMaxImageSide || encoded.height > kMaxImageSide) {
        diag.fail(encoded.element, std::to_string(encoded.width) + " × " +
                                       std::to_string(encoded.height) + " texels: more than the " +
                                       std::to_string(kMaxImageSide) + " per side mcrt reads");
    }
}

// Deflate's largest expansion: a 258-byte match costs at least 2 bits (RFC 1951 sec. 3.2.5), so
// no compressed byte inflates to more than 1032.
constexpr unsigned long long kMaxInflateRatio = 1032;

// PNG's chunk layout (png_structure.h), read before stb_image sees the file: IHDR first (its
// size checked against the limits before anything else: stb_image refuses to report a size it
// thinks too large), then every chunk and its CRC, and IDAT data that can inflate to the samples
// IHDR declares at deflate's largest ratio: stb_image allocates the whole image before it finds
// too few, so 100 bytes declaring 16384² would cost it a gigabyte. A file cut short is named
// here; stb_image would read on past its end as zeros. The IDAT data itself is inflated and
// counted when the image is decoded (check_png_samples).
void read_png_header(Encoded& encoded, const Diagnostics& diag) {
    std::string why = read_png_layout(encoded.data, encoded.size, encoded.png, true);
    if (!why.empty()) diag.fail(encoded.element, why);
    encoded.width = encoded.png.width;
    encoded.height = encoded.png.height;
    check_size(encoded, diag);
    why = read_png_layout(encoded.data, encoded.size, encoded.png);
    if (!why.empty()) diag.fail(encoded.element, why);
    if (encoded.png.idat_bytes * kMaxInflateRatio < png_filtered_bytes(encoded.png)) {
        diag.fail(encoded.element, "the PNG's " + std::to_string(encoded.png.idat_bytes) +
                                       " bytes of IDAT data cannot hold the " +
                                       std::to_string(encoded.width) + " × " +
                                       std::to_string(encoded.height) + " texels it declares");
    }
    // stb_image allocates each of its buffers only up to INT_MAX bytes (stbi__mad3sizes_valid),
    // the inflated scanlines' size in an int: 16-bit RGB(A) at 16384² fails it, after a full
    // inflate, under another decoder's error ("no SOI"). Its image has 4 channels for colour and
    // palette, up to 2 for grey.
    const uint64_t image_bytes =
        uint64_t(encoded.width) * encoded.height *
        (encoded.png.colour_type == 0 || encoded.png.colour_type == 4 ? 2 : 4) *
        (encoded.png.depth == 16 ? 2 : 1);
    const uint64_t largest = std::max(image_bytes, png_filtered_bytes(encoded.png));
    if (largest > uint64_t(INT_MAX)) {
        diag.fail(encoded.element, std::to_string(encoded.width) + " × " +
                                       std::to_string(encoded.height) + " texels of " +
                                       std::to_string(encoded.png.depth) +
                                       "-bit samples need a buffer of " + std::to_string(largest) +
                                       " bytes, more than the 2 GiB stb_image (mcrt's decoder) "
                                       "allocates at once");
    }
}

// The JPEG's frame header (jpeg_structure.h): a coding stb_image reads, a size within the limits
// and one the file's bytes can hold. stb_image allocates the declared image whole and decodes a
// scan that runs out as zeros.
void read_jpeg_header(Encoded& encoded, const Diagnostics& diag) {
    JpegFrame& frame = encoded.jpeg;
    const std::string why = read_jpeg_frame(encoded.data, encoded.size, frame);
    if (!why.empty()) diag.fail(encoded.element, why);
    encoded.width = frame.width;
    encoded.height = frame.height;
    check_size(encoded, diag);
    const uint64_t least = jpeg_min_bytes(frame);
    if (encoded.size < least) {
        diag.fail(encoded.element,
                  "the JPEG's " + std::to_string(encoded.size) + " bytes cannot hold the " +
                      std::to_string(frame.width) + " × " + std::to_string(frame.height) +
                      " texels it declares: its " + std::to_string(frame.blocks) +
                      " blocks of 8 × 8 need at least " + std::to_string(least) + " (a bit each)");
    }
}

// What decoding `encoded` holds at most, every buffer of every stage counted as if all were held
// at once (an upper bound), from the stages of stb_image 2.27 and mcrt's copy of the texels:
// PNG: the IDAT data gathered (up to twice its size as it grows), the inflated scanlines, the
// image at its bit depth and up to 4 channels, the same as 8-bit RGBA; JPEG: the component planes
// padded to whole MCUs, a byte each and two bytes of coefficient more when progressive, and the
// 8-bit RGBA image. Both: mcrt's copy (TextureImage::rgba).
uint64_t decode_bytes(const Encoded& encoded) {
    const uint64_t rgba = uint64_t(encoded.width) * encoded.height * 4;
    if (encoded.format == Format::Png) {
        const PngLayout& png = encoded.png;
        return 2 * png.idat_bytes + png_filtered_bytes(png) + rgba * (png.depth == 16 ? 2 : 1) +
               rgba + rgba;
    }
    return encoded.jpeg.padded_samples * (encoded.jpeg.progressive() ? 3 : 1) + rgba + rgba;
}

// The header of `encoded`: its size (within the limits) and stb_image's acceptance of it.
void read_header(Encoded& encoded, const Diagnostics& diag) {
    if (encoded.size > size_t(INT_MAX)) {
        diag.fail(encoded.element, "the encoded image is larger than 2 GiB");
    }
    if (encoded.format == Format::Png) {
        read_png_header(encoded, diag);
    } else {
        read_jpeg_header(encoded, diag);
    }
    int width = 0, height = 0, components = 0;
    if (!stbi_info_from_memory(encoded.data, int(encoded.size), &width, &height, &components)) {
        const char* reason = stbi_failure_reason();
        diag.fail(encoded.element, std::string("the ") + format_name(encoded.format) +
                                       " header is corrupt" +
                                       (reason && *reason ? std::string(": ") + reason : ""));
    }
    if (unsigned(width) != encoded.width || unsigned(height) != encoded.height) {
        diag.fail(encoded.element, "stb_image reads another size than its header's");
    }
    encoded.decode_bytes = decode_bytes(encoded);
}

// One image decoded to RGBA: grey, grey + alpha, RGB and palettes widened, 16-bit samples
// reduced to their high byte, alpha 255 where the file has none; row 0 the top row, as stored.
TextureImage decode(const tinygltf::Image& image, size_t index, const Encoded& encoded,
                    const Diagnostics& diag) {
    if (encoded.format == Format::Png) {
        const std::string why = check_png_samples(encoded.data, encoded.png);
        if (!why.empty()) diag.fail(encoded.element, why);
    }
    int width = 0, height = 0, components = 0;
    stbi_uc* texels =
        stbi_load_from_memory(encoded.data, int(encoded.size), &width, &height, &components, 4);
    if (!texels) {
        const char* reason = stbi_failure_reason();  // thread-local in libstb
        diag.fail(encoded.element, std::string("the ") + format_name(encoded.format) +
                                       " cannot be decoded" +
                                       (reason && *reason ? std::string(": ") + reason : ""));
    }
    TextureImage decoded;
    decoded.name = image.uri.empty() ? element_name("image", index) : image.uri;
    decoded.width = uint32_t(width);
    decoded.height = uint32_t(height);
    const bool as_declared = decoded.width == encoded.width && decoded.height == encoded.height;
    if (as_declared) {
        try {
            decoded.rgba.assign(texels, texels + size_t(width) * size_t(height) * 4);
        } catch (...) {
            stbi_image_free(texels);
            throw;
        }
    }
    stbi_image_free(texels);
    if (!as_declared) diag.fail(encoded.element, "decoded to another size than its header's");
    return decoded;
}

}  // namespace

std::vector<TextureImage> decode_images(const tinygltf::Model& model,
                                        const std::vector<int>& sources, const Diagnostics& diag,
                                        unsigned threads) {
    // Every header first: a scene over the limits is refused before a texel is allocated.
    std::vector<Encoded> encoded(sources.size());
    unsigned long long texels = 0;
    for (size_t k = 0; k < sources.size(); ++k) {
        const size_t index = size_t(sources[k]);  // checked by the texture that names it
        const tinygltf::Image& image = model.images.at(index);
        encoded[k].element = image_element(image, index);
        locate_bytes(model, image, encoded[k], diag);
        identify_format(image, encoded[k], diag);
        read_header(encoded[k], diag);
        texels += (unsigned long long)encoded[k].width * encoded[k].height;
        if (texels > kMaxImageTexels) {
            diag.fail(encoded[k].element, "the images the materials use hold " +
                                              std::to_string(texels) +
                                              " texels up to this one, more than the " +
                                              std::to_string(kMaxImageTexels) + " mcrt reads");
        }
    }

    // Then the texels, images handed out one at a time, in order, to the threads, each starting
    // once the decoders' estimates in flight leave room for its own (kMaxDecodingBytes; alone
    // when it is larger); each failure is kept with its image, and the first in `sources` order
    // is the one reported.
    std::vector<TextureImage> images(sources.size());
    std::vector<std::exception_ptr> failures(sources.size());
    std::mutex mutex;
    std::condition_variable room;
    size_t next = 0;
    uint64_t in_flight = 0;
    auto work = [&] {
        while (true) {
            std::unique_lock<std::mutex> lock(mutex);
            if (next == sources.size()) return;
            const size_t k = next++;
            const uint64_t need = encoded[k].decode_bytes;
            room.wait(lock,
                      [&] { return in_flight == 0 || in_flight + need <= kMaxDecodingBytes; });
            in_flight += need;
            lock.unlock();
            try {
                const size_t index = size_t(sources[k]);
                images[k] = decode(model.images[index], index, encoded[k], diag);
            } catch (...) {
                failures[k] = std::current_exception();
            }
            lock.lock();
            in_flight -= need;
            room.notify_all();
        }
    };
    if (threads == 0) threads = std::min(8u, std::max(1u, std::thread::hardware_concurrency()));
    threads = unsigned(std::min<size_t>(threads, sources.size()));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) {
        try {
            pool.emplace_back(work);
        } catch (const std::system_error&) {
            break;  // no more threads to be had: those running share the rest
        }
    }
    work();
    for (std::thread& t : pool) t.join();
    for (const std::exception_ptr& failure : failures) {
        if (failure) std::rethrow_exception(failure);
    }
    return images;
}

}  // namespace mcrt::gltf
