// A JPEG file's frame checked before a decoder allocates for it (ITU-T T.81): the coding its SOF
// marker names, and a declared size the file's bytes can hold. stb_image reads baseline and
// progressive Huffman JPEG of 8-bit samples and calls every other coding corrupt; it allocates
// the whole declared image and decodes a scan that runs out as zeros, so 451 bytes declaring
// 8192 × 8192 texels cost 853 MB.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace mcrt {

// What the frame header (SOFn, T.81 B.2.2) declares.
struct JpegFrame {
    unsigned marker = 0;     // 0xC0 to 0xCF
    unsigned precision = 0;  // bits per sample
    uint32_t width = 0, height = 0;
    unsigned components = 0;
    uint64_t blocks = 0;  // 8×8 blocks over all components, at their sampling factors
    // Samples over all components padded to whole MCUs (T.81 A.2.4): what a decoder's component
    // planes hold (stb_image: a byte each, and two more bytes of coefficient each when
    // progressive).
    uint64_t padded_samples = 0;
    bool progressive() const { return marker == 0xC2; }
};

// Reads the markers of the JPEG bytes [data, data + size) from SOI to the first frame header.
// "" when the frame is one stb_image decodes, else the reason: a coding it lacks named
// ("the JPEG is lossless (SOF3), ..."), or a malformed marker segment.
std::string read_jpeg_frame(const unsigned char* data, size_t size, JpegFrame& frame);

// The fewest bytes whose scans can code `frame`'s blocks: each block of each component takes at
// least one Huffman code, of at least one bit, in its first (DC) scan (T.81 F.1.2.1, G.1.2.1).
uint64_t jpeg_min_bytes(const JpegFrame& frame);

}  // namespace mcrt
