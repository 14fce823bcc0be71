// A PNG file's structure checked before a decoder allocates for it (PNG, ISO/IEC 15948:2004):
// its chunks and their CRCs, then its image data inflated in fixed pieces and counted against
// what IHDR declares. stb_image checks neither CRC nor Adler-32, inflates IDAT into a buffer that
// doubles until the stream ends (1 MB of deflate reaches 1 GB whatever IHDR says), and decodes a
// palette index beyond the palette as transparent black.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mcrt {

// What IHDR, PLTE and the IDAT chunks say.
struct PngLayout {
    uint32_t width = 0, height = 0;
    uint8_t depth = 0, colour_type = 0;
    bool interlaced = false;                      // Adam7
    uint32_t palette_entries = 0;                 // PLTE's, for colour type 3
    uint64_t idat_bytes = 0;                      // over all IDAT chunks
    std::vector<std::pair<size_t, size_t>> idat;  // each IDAT's data: offset, length
};

// Walks the chunks of the PNG bytes [data, data + size), whose 8-byte signature the caller has
// checked: IHDR first and whole with a valid colour type, bit depth and methods, every chunk
// inside the bytes with its CRC-32 right, no critical chunk but IHDR, PLTE, IDAT and IEND, a
// PLTE for a palette image, IEND reached. "" when sound, else the reason: "the PNG is truncated:
// ...", "PNG chunk IDAT at byte 41: CRC mismatch". IHDR alone is read when `ihdr_only`, so that
// the declared size can be checked against the limits before anything else.
std::string read_png_layout(const unsigned char* data, size_t size, PngLayout& layout,
                            bool ihdr_only = false);

// Bits per texel: the bit depth times the samples of the colour type.
unsigned png_bits_per_texel(const PngLayout& layout);

// The bytes of filtered scanlines the declared size needs (a filter byte per row; the seven
// Adam7 passes when interlaced): exactly what the IDAT data must inflate to.
uint64_t png_filtered_bytes(const PngLayout& layout);

// Inflates the IDAT data in fixed pieces, holding two rows at most: a zlib stream whose
// Adler-32 matches, inflating to exactly png_filtered_bytes (refused as soon as it passes that),
// each row's filter type 0 to 4, and, for a palette image, every index within the palette.
// "" when sound, else the reason.
std::string check_png_samples(const unsigned char* data, const PngLayout& layout);

}  // namespace mcrt
