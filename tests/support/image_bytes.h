// Image files built byte by byte for the texture tests: PNGs of every colour type and depth
// (stored, uncompressed deflate blocks; CRC-32 and Adler-32 computed here), and data: URIs.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace mcrt::test {

using Bytes = std::vector<unsigned char>;

// CRC-32 of PNG chunks (ISO/IEC 15948 Annex D), bit by bit.
inline uint32_t png_crc32(const unsigned char* data, size_t size) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < size; ++i) {
        crc ^= data[i];
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return crc ^ 0xFFFFFFFFu;
}

inline void put_be32(Bytes& out, uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) out.push_back((unsigned char)(v >> shift));
}

// One chunk: length, type, data, CRC of type and data.
inline Bytes png_chunk(const std::string& type, const Bytes& data) {
    Bytes chunk;
    put_be32(chunk, uint32_t(data.size()));
    Bytes typed(type.begin(), type.end());
    typed.insert(typed.end(), data.begin(), data.end());
    chunk.insert(chunk.end(), typed.begin(), typed.end());
    put_be32(chunk, png_crc32(typed.data(), typed.size()));
    return chunk;
}

inline Bytes png_ihdr(uint32_t width, uint32_t height, uint8_t depth, uint8_t colour_type) {
    Bytes data;
    put_be32(data, width);
    put_be32(data, height);
    data.insert(data.end(), {depth, colour_type, 0, 0, 0});
    return png_chunk("IHDR", data);
}

// A zlib stream (RFC 1950) of stored deflate blocks (RFC 1951 sec. 3.2.4).
inline Bytes zlib_stored(const Bytes& raw) {
    Bytes out = {0x78, 0x01};
    size_t at = 0;
    do {
        const size_t n = std::min<size_t>(raw.size() - at, 65535);
        out.push_back(at + n == raw.size() ? 1 : 0);
        out.push_back((unsigned char)(n & 0xFF));
        out.push_back((unsigned char)(n >> 8));
        out.push_back((unsigned char)(~n & 0xFF));
        out.push_back((unsigned char)((~n >> 8) & 0xFF));
        out.insert(out.end(), raw.begin() + long(at), raw.begin() + long(at + n));
        at += n;
    } while (at < raw.size());
    uint32_t a = 1, b = 0;
    for (unsigned char c : raw) {
        a = (a + c) % 65521;
        b = (b + a) % 65521;
    }
    put_be32(out, (b << 16) | a);
    return out;
}

inline const Bytes& png_signature() {
    static const Bytes signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    return signature;
}

// A PNG of `rows` (height rows of packed samples, as the colour type and depth store them, each
// given a filter byte 0 here); `chunks` (PLTE, tRNS, gAMA, ...) go between IHDR and IDAT.
inline Bytes png_file(uint32_t width, uint8_t depth, uint8_t colour_type,
                      const std::vector<Bytes>& rows, const std::vector<Bytes>& chunks = {}) {
    Bytes raw;
    for (const Bytes& row : rows) {
        raw.push_back(0);
        raw.insert(raw.end(), row.begin(), row.end());
    }
    Bytes png = png_signature();
    const Bytes ihdr = png_ihdr(width, uint32_t(rows.size()), depth, colour_type);
    png.insert(png.end(), ihdr.begin(), ihdr.end());
    for (const Bytes& chunk : chunks) png.insert(png.end(), chunk.begin(), chunk.end());
    const Bytes idat = png_chunk("IDAT", zlib_stored(raw));
    png.insert(png.end(), idat.begin(), idat.end());
    const Bytes iend = png_chunk("IEND", {});
    png.insert(png.end(), iend.begin(), iend.end());
    return png;
}

// A PNG that declares `width` × `height` RGBA texels and holds none of them: signature, IHDR, an
// IDAT of `idat_bytes` zeros (none when 0; never valid zlib), IEND.
inline Bytes png_header_only(uint32_t width, uint32_t height, size_t idat_bytes = 0) {
    Bytes png = png_signature();
    const Bytes ihdr = png_ihdr(width, height, 8, 6);
    png.insert(png.end(), ihdr.begin(), ihdr.end());
    if (idat_bytes > 0) {
        const Bytes idat = png_chunk("IDAT", Bytes(idat_bytes, 0));
        png.insert(png.end(), idat.begin(), idat.end());
    }
    const Bytes iend = png_chunk("IEND", {});
    png.insert(png.end(), iend.begin(), iend.end());
    return png;
}

inline std::string base64(const Bytes& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) v |= bytes[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

inline std::string data_uri(const std::string& mime, const Bytes& bytes) {
    return "data:" + mime + ";base64," + base64(bytes);
}

}  // namespace mcrt::test
