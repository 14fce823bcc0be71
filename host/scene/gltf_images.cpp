// Decoding glTF images with stb_image (Debian's libstb, which holds the implementation): the
// encoded bytes located and identified, every header checked against the limits, then the images
// decoded on several threads into Scene::images.
#include "scene/gltf_images.h"

#include <stb/stb_image.h>

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstring>
#include <exception>
#include <system_error>
#include <thread>

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
};

uint32_t big_endian_32(const unsigned char* p) {
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

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

// PNG's chunk layout (ISO/IEC 15948 sec. 5.3), walked before stb_image reads the file: IHDR
// first (its size read and checked here, before anything else: stb_image refuses to report a
// size it thinks too large), IEND reached within the bytes, no critical chunk stb_image does not
// know, and IDAT data that can inflate to the samples IHDR declares: stb_image allocates the whole
// image before it finds too few, so 100 bytes declaring 16384² would cost it a gigabyte. A file
// cut short is named here; stb_image would read on past its end as zeros.
void walk_png_chunks(Encoded& encoded, const Diagnostics& diag) {
    const unsigned char* d = encoded.data;
    const size_t n = encoded.size;
    size_t at = 8;
    unsigned long long sample_bits = 0, idat_bytes = 0;
    for (bool first = true;; first = false) {
        if (n - at < 12) {
            diag.fail(encoded.element, "the PNG is truncated: " + std::to_string(n) +
                                           " bytes end before its IEND chunk");
        }
        const uint32_t length = big_endian_32(d + at);
        const std::string type(reinterpret_cast<const char*>(d + at + 4), 4);
        if (first) {
            if (type != "IHDR" || length != 13 || n - at < 12 + 13) {
                diag.fail(encoded.element, "the PNG does not start with a whole IHDR chunk");
            }
            encoded.width = big_endian_32(d + at + 8);
            encoded.height = big_endian_32(d + at + 12);
            check_size(encoded, diag);
            const unsigned depth = d[at + 16], colour_type = d[at + 17];
            const unsigned samples[7] = {1, 0, 3, 1, 2, 0, 4};  // per texel, by colour type
            sample_bits = (unsigned long long)encoded.width * encoded.height * depth *
                          (colour_type < 7 ? samples[colour_type] : 0);
        }
        if (length > n - at - 12) {
            diag.fail(encoded.element, "the PNG is truncated: its chunk at byte " +
                                           std::to_string(at) + " holds " + std::to_string(length) +
                                           " bytes, " + std::to_string(n - at - 12) + " remain");
        }
        if (type == "IDAT") idat_bytes += length;
        if (type == "IEND") {
            if (idat_bytes * kMaxInflateRatio < sample_bits / 8) {
                diag.fail(encoded.element, "the PNG's " + std::to_string(idat_bytes) +
                                               " bytes of IDAT data cannot hold the " +
                                               std::to_string(encoded.width) + " × " +
                                               std::to_string(encoded.height) +
                                               " texels it declares");
            }
            return;
        }
        const bool critical = (d[at + 4] & 0x20) == 0;  // ancillary chunks: gAMA, iCCP, ... skipped
        if (critical && type != "IHDR" && type != "PLTE" && type != "IDAT" && type != "CgBI") {
            diag.fail(encoded.element, "the PNG holds a critical chunk of unknown type");
        }
        at += 12 + length;
    }
}

// The header of `encoded`: its size (within the limits) and stb_image's acceptance of it.
void read_header(Encoded& encoded, const Diagnostics& diag) {
    if (encoded.size > size_t(INT_MAX)) {
        diag.fail(encoded.element, "the encoded image is larger than 2 GiB");
    }
    if (encoded.format == Format::Png) walk_png_chunks(encoded, diag);
    int width = 0, height = 0, components = 0;
    if (!stbi_info_from_memory(encoded.data, int(encoded.size), &width, &height, &components)) {
        const char* reason = stbi_failure_reason();
        diag.fail(encoded.element, std::string("the ") + format_name(encoded.format) +
                                       " header is corrupt" +
                                       (reason && *reason ? std::string(": ") + reason : ""));
    }
    if (encoded.format == Format::Jpeg) {
        encoded.width = unsigned(width);
        encoded.height = unsigned(height);
        check_size(encoded, diag);
    }
}

// One image decoded to RGBA: grey, grey + alpha, RGB and palettes widened, 16-bit samples
// reduced to their high byte, alpha 255 where the file has none; row 0 the top row, as stored.
TextureImage decode(const tinygltf::Image& image, size_t index, const Encoded& encoded,
                    const Diagnostics& diag) {
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

    // Then the texels, images handed out one at a time to the threads; each failure is kept
    // with its image, and the first in `sources` order is the one reported.
    std::vector<TextureImage> images(sources.size());
    std::vector<std::exception_ptr> failures(sources.size());
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t k; (k = next.fetch_add(1)) < sources.size();) {
            try {
                const size_t index = size_t(sources[k]);
                images[k] = decode(model.images[index], index, encoded[k], diag);
            } catch (...) {
                failures[k] = std::current_exception();
            }
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
