#include "image/jpeg_structure.h"

#include <algorithm>

namespace mcrt {

namespace {

unsigned big_endian_16(const unsigned char* p) { return unsigned(p[0]) << 8 | p[1]; }

// T.81 Table B.1: the frame markers, C4 (DHT), C8 (JPG) and CC (DAC) excepted.
bool is_frame_marker(unsigned m) {
    return m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
}

// The coding a frame marker names, for the codings stb_image does not read; nullptr for the
// ones it does (SOF0 baseline, SOF1 extended sequential, SOF2 progressive, all Huffman).
const char* unsupported_coding(unsigned m) {
    switch (m) {
        case 0xC3:
            return "lossless";
        case 0xC5:
            return "hierarchical (differential sequential)";
        case 0xC6:
            return "hierarchical (differential progressive)";
        case 0xC7:
            return "hierarchical lossless";
        case 0xC9:
            return "arithmetic-coded (extended sequential)";
        case 0xCA:
            return "arithmetic-coded progressive";
        case 0xCB:
            return "arithmetic-coded lossless";
        case 0xCD:
            return "arithmetic-coded hierarchical (differential sequential)";
        case 0xCE:
            return "arithmetic-coded hierarchical (differential progressive)";
        case 0xCF:
            return "arithmetic-coded hierarchical lossless";
    }
    return nullptr;
}

std::string hex(unsigned m) {
    const char* digits = "0123456789ABCDEF";
    return std::string("0x") + digits[m >> 4 & 15] + digits[m & 15];
}

const char* const kRead =
    "the decoder mcrt uses (stb_image) reads baseline and progressive Huffman JPEG of 8-bit "
    "samples";

// The frame header's fields at `segment` (after the marker: length, P, Y, X, Nf, components).
std::string read_frame_header(const unsigned char* segment, unsigned length, unsigned marker,
                              JpegFrame& frame) {
    frame.marker = marker;
    if (length < 8) return "the JPEG's SOF segment is too short";
    frame.precision = segment[2];
    frame.height = big_endian_16(segment + 3);
    frame.width = big_endian_16(segment + 5);
    frame.components = segment[7];
    const std::string sof = "SOF" + std::to_string(marker - 0xC0);
    if (const char* coding = unsupported_coding(marker)) {
        return std::string("the JPEG is ") + coding + " (" + sof + "), a coding that " + kRead;
    }
    if (frame.precision != 8) {
        return "the JPEG has " + std::to_string(frame.precision) + "-bit samples (" + sof +
               "), which " + kRead + " only";
    }
    if (frame.height == 0) {
        return std::string("the JPEG's height comes after its first scan (a DNL marker), which ") +
               kRead + " does not handle";
    }
    if (frame.components == 0 || length != 8 + 3 * frame.components) {
        return "the JPEG's SOF segment of " + std::to_string(length) + " bytes does not hold " +
               std::to_string(frame.components) + " components";
    }
    // Each component's texels at its sampling factors (T.81 A.1.1), in whole 8×8 blocks.
    unsigned h_max = 1, v_max = 1;
    for (unsigned c = 0; c < frame.components; ++c) {
        const unsigned sampling = segment[8 + 3 * c + 1];
        h_max = std::max(h_max, sampling >> 4);
        v_max = std::max(v_max, sampling & 15u);
    }
    const uint64_t mcus_x = (frame.width + 8 * h_max - 1) / (8 * h_max);
    const uint64_t mcus_y = (frame.height + 8 * v_max - 1) / (8 * v_max);
    frame.blocks = frame.padded_samples = 0;
    for (unsigned c = 0; c < frame.components; ++c) {
        const unsigned sampling = segment[8 + 3 * c + 1];
        const unsigned h = std::max(1u, sampling >> 4), v = std::max(1u, sampling & 15u);
        const uint64_t x = (uint64_t(frame.width) * h + h_max - 1) / h_max;
        const uint64_t y = (uint64_t(frame.height) * v + v_max - 1) / v_max;
        frame.blocks += ((x + 7) / 8) * ((y + 7) / 8);
        frame.padded_samples += (mcus_x * h * 8) * (mcus_y * v * 8);
    }
    return "";
}

}  // namespace

std::string read_jpeg_frame(const unsigned char* data, size_t size, JpegFrame& frame) {
    frame = JpegFrame{};
    size_t at = 2;  // after SOI, which the caller identified the file by
    while (true) {
        // A marker: 0xFF, fill bytes 0xFF, then its code (T.81 B.1.1.2).
        if (at >= size || data[at] != 0xFF) {
            return "the JPEG has no frame header (SOF) where a marker is expected, at byte " +
                   std::to_string(at);
        }
        while (at < size && data[at] == 0xFF) ++at;
        if (at >= size) return "the JPEG is truncated before its frame header (SOF)";
        const unsigned marker = data[at++];
        if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) continue;  // no length
        if (marker == 0xD9 || marker == 0xDA) {
            return "the JPEG has no frame header (SOF) before its " +
                   std::string(marker == 0xD9 ? "end (EOI)" : "first scan (SOS)");
        }
        if (size - at < 2) return "the JPEG is truncated before its frame header (SOF)";
        const unsigned length = big_endian_16(data + at);
        if (length < 2 || length > size - at) {
            return "the JPEG is truncated: its marker " + hex(marker) + " segment at byte " +
                   std::to_string(at - 2) + " holds " + std::to_string(length) + " bytes, " +
                   std::to_string(size - at) + " remain";
        }
        if (marker == 0xCC) {
            // DAC: arithmetic-coding conditioning, before an arithmetic frame's scans.
            return std::string("the JPEG is arithmetic-coded (a DAC marker), a coding that ") +
                   kRead;
        }
        if (is_frame_marker(marker)) return read_frame_header(data + at, length, marker, frame);
        at += length;
    }
}

uint64_t jpeg_min_bytes(const JpegFrame& frame) { return (frame.blocks + 7) / 8; }

}  // namespace mcrt
