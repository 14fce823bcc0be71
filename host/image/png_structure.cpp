#include "image/png_structure.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <new>

namespace mcrt {

namespace {

uint32_t big_endian_32(const unsigned char* p) {
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

// Samples per texel by colour type (PNG 11.2.2, Table 11.1); 0: no such colour type.
unsigned samples_of(unsigned colour_type) {
    constexpr unsigned kSamples[7] = {1, 0, 3, 1, 2, 0, 4};
    return colour_type < 7 ? kSamples[colour_type] : 0;
}

// PNG 11.2.2, Table 11.1: the bit depths each colour type allows.
bool depth_allowed(unsigned colour_type, unsigned depth) {
    switch (colour_type) {
        case 0:
            return depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16;
        case 3:
            return depth == 1 || depth == 2 || depth == 4 || depth == 8;
        case 2:
        case 4:
        case 6:
            return depth == 8 || depth == 16;
    }
    return false;
}

std::string read_ihdr(const unsigned char* field, PngLayout& layout) {
    layout.width = big_endian_32(field);
    layout.height = big_endian_32(field + 4);
    layout.depth = field[8];
    layout.colour_type = field[9];
    if (!depth_allowed(layout.colour_type, layout.depth)) {
        return "the PNG's IHDR declares colour type " + std::to_string(layout.colour_type) +
               " with bit depth " + std::to_string(layout.depth) +
               ", which PNG does not define (PNG 11.2.2)";
    }
    if (field[10] != 0 || field[11] != 0 || field[12] > 1) {
        return "the PNG's IHDR declares compression method " + std::to_string(field[10]) +
               ", filter method " + std::to_string(field[11]) + ", interlace method " +
               std::to_string(field[12]) + ": PNG defines 0, 0 and 0 or 1";
    }
    layout.interlaced = field[12] == 1;
    return "";
}

// Adam7 (PNG 8.2): each pass's first column and row and its steps.
struct Pass {
    uint32_t x0, y0, dx, dy;
};
constexpr std::array<Pass, 7> kAdam7 = {{{0, 0, 8, 8},
                                         {4, 0, 8, 8},
                                         {0, 4, 4, 8},
                                         {2, 0, 4, 4},
                                         {0, 2, 2, 4},
                                         {1, 0, 2, 2},
                                         {0, 1, 1, 2}}};
constexpr Pass kWhole = {0, 0, 1, 1};

uint32_t pass_extent(uint32_t size, uint32_t start, uint32_t step) {
    return size > start ? (size - start + step - 1) / step : 0;
}

// The inflated image data, fed piece by piece, cut into the rows of each pass: each row's filter
// type checked and, for a palette image, the row unfiltered (PNG 9.2-9.4, filter unit one byte)
// and its indices checked against the palette.
class RowWalker {
  public:
    explicit RowWalker(const PngLayout& layout) : layout_(layout) {
        bits_ = png_bits_per_texel(layout);
        if (layout.interlaced) {
            for (const Pass& p : kAdam7) passes_.push_back(p);
        } else {
            passes_.push_back(kWhole);
        }
        start_pass(0);
    }

    // `size` more bytes; "" or why they are not image data of the declared size. A row's
    // samples are passed over whole (copied for a palette image): only filter bytes are read.
    std::string feed(const unsigned char* data, size_t size) {
        for (size_t i = 0; i < size;) {
            if (pass_ == passes_.size()) return "the PNG's IDAT data inflates beyond its rows";
            if (column_ == 0) {
                if (data[i] > 4) {
                    return "the PNG's row " + std::to_string(image_row()) + pass_name() +
                           " has filter type " + std::to_string(data[i]) + " (PNG defines 0 to 4)";
                }
                filter_ = data[i++];
                column_ = 1;
            } else {
                const size_t n = size_t(std::min<uint64_t>(size - i, row_bytes_ + 1 - column_));
                if (palette()) std::memcpy(row_.data() + (column_ - 1), data + i, n);
                i += n;
                column_ += n;
            }
            if (column_ == row_bytes_ + 1) {
                if (palette()) {
                    const std::string why = finish_palette_row();
                    if (!why.empty()) return why;
                }
                column_ = 0;
                if (++row_index_ == pass_height_) start_pass(pass_ + 1);
            }
        }
        return "";
    }

  private:
    bool palette() const { return layout_.colour_type == 3; }

    uint64_t image_row() const {
        return passes_[pass_].y0 + uint64_t(row_index_) * passes_[pass_].dy;
    }
    std::string pass_name() const {
        return layout_.interlaced ? " (Adam7 pass " + std::to_string(pass_ + 1) + ")" : "";
    }

    // The next pass with texels, from `pass` on; passes_.size() once none is left.
    void start_pass(size_t pass) {
        for (pass_ = pass; pass_ < passes_.size(); ++pass_) {
            const Pass& p = passes_[pass_];
            pass_width_ = pass_extent(layout_.width, p.x0, p.dx);
            pass_height_ = pass_extent(layout_.height, p.y0, p.dy);
            if (pass_width_ > 0 && pass_height_ > 0) break;
        }
        row_index_ = 0;
        column_ = 0;
        if (pass_ == passes_.size()) return;
        row_bytes_ = (uint64_t(pass_width_) * bits_ + 7) / 8;
        if (palette()) {
            row_.assign(row_bytes_, 0);
            previous_.assign(row_bytes_, 0);  // the row above a pass's first is zero (PNG 9.2)
        }
    }

    std::string finish_palette_row() {
        // Reconstruction with a filter unit of one byte (bit depths up to 8), PNG 9.2-9.4.
        for (size_t i = 0; i < row_bytes_; ++i) {
            const int a = i > 0 ? row_[i - 1] : 0, b = previous_[i],
                      c = i > 0 ? previous_[i - 1] : 0;
            int predictor = 0;
            switch (filter_) {
                case 1:
                    predictor = a;
                    break;
                case 2:
                    predictor = b;
                    break;
                case 3:
                    predictor = (a + b) / 2;
                    break;
                case 4: {
                    const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b),
                              pc = std::abs(p - c);
                    predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
                    break;
                }
            }
            row_[i] = static_cast<unsigned char>(row_[i] + predictor);
        }
        const unsigned depth = layout_.depth, mask = (1u << depth) - 1;
        for (uint32_t k = 0; k < pass_width_; ++k) {
            const uint64_t bit = uint64_t(k) * depth;
            const unsigned index = (row_[bit / 8] >> (8 - depth - bit % 8)) & mask;
            if (index >= layout_.palette_entries) {
                const Pass& p = passes_[pass_];
                return "the PNG's texel (" + std::to_string(p.x0 + uint64_t(k) * p.dx) + ", " +
                       std::to_string(image_row()) + ") has palette index " +
                       std::to_string(index) + ", beyond its " +
                       std::to_string(layout_.palette_entries) + "-colour palette";
            }
        }
        previous_.swap(row_);
        return "";
    }

    const PngLayout& layout_;
    unsigned bits_ = 0;
    std::vector<Pass> passes_;
    size_t pass_ = 0;
    uint32_t pass_width_ = 0, pass_height_ = 0, row_index_ = 0;
    uint64_t row_bytes_ = 0, column_ = 0;  // column 0 is the filter byte
    unsigned filter_ = 0;
    std::vector<unsigned char> row_, previous_;  // palette images only
};

// zlib's stream, ended however the check ends.
struct Inflater {
    z_stream stream{};
    Inflater() {
        if (inflateInit(&stream) != Z_OK) throw std::bad_alloc();
    }
    ~Inflater() { inflateEnd(&stream); }
    Inflater(const Inflater&) = delete;
    Inflater& operator=(const Inflater&) = delete;
};

}  // namespace

std::string read_png_layout(const unsigned char* data, size_t size, PngLayout& layout,
                            bool ihdr_only) {
    layout = PngLayout{};
    size_t at = 8;
    for (bool first = true;; first = false) {
        if (size - at < 12) {
            return "the PNG is truncated: " + std::to_string(size) +
                   " bytes end before its IEND chunk";
        }
        const uint32_t length = big_endian_32(data + at);
        const std::string type(reinterpret_cast<const char*>(data + at + 4), 4);
        if (first && (type != "IHDR" || length != 13 || size - at < 12 + 13)) {
            return "the PNG does not start with a whole IHDR chunk";
        }
        if (length > size - at - 12) {
            return "the PNG is truncated: its chunk at byte " + std::to_string(at) + " holds " +
                   std::to_string(length) + " bytes, " + std::to_string(size - at - 12) + " remain";
        }
        const unsigned char* field = data + at + 8;
        if (big_endian_32(field + length) != crc32(0, data + at + 4, uInt(4 + length))) {
            // PNG 5.3: the CRC covers the chunk type and data. A decoder that skips it (as
            // stb_image does) reads damaged bytes as texels.
            return "PNG chunk " + type + " at byte " + std::to_string(at) + ": CRC mismatch";
        }
        if (first) {
            const std::string why = read_ihdr(field, layout);
            if (!why.empty() || ihdr_only) return why;
        } else if (type == "IHDR") {
            return "the PNG has a second IHDR chunk at byte " + std::to_string(at);
        }
        if (type == "PLTE") {
            if (length == 0 || length % 3 != 0 || length > 3 * 256) {
                return "the PNG's PLTE chunk holds " + std::to_string(length) +
                       " bytes, not 1 to 256 RGB entries";
            }
            layout.palette_entries = length / 3;
        } else if (type == "IDAT") {
            layout.idat.emplace_back(at + 8, length);
            layout.idat_bytes += length;
        } else if (type == "IEND") {
            if (layout.colour_type == 3 && layout.palette_entries == 0) {
                return "the PNG is a palette image without a PLTE chunk";
            }
            if (layout.idat.empty()) return "the PNG has no IDAT chunk";
            return "";
        } else if ((data[at + 4] & 0x20) == 0 && type != "IHDR") {
            // Critical chunks (bit 5 of the first byte clear) must be understood; ancillary
            // ones (gAMA, iCCP, ...) are skipped.
            return "the PNG holds a critical chunk of unknown type";
        }
        at += 12 + length;
    }
}

unsigned png_bits_per_texel(const PngLayout& layout) {
    return layout.depth * samples_of(layout.colour_type);
}

uint64_t png_filtered_bytes(const PngLayout& layout) {
    const uint64_t bits = png_bits_per_texel(layout);
    auto pass_bytes = [&](const Pass& p) {
        const uint64_t w = pass_extent(layout.width, p.x0, p.dx);
        const uint64_t h = pass_extent(layout.height, p.y0, p.dy);
        return w > 0 && h > 0 ? h * (1 + (w * bits + 7) / 8) : 0;
    };
    if (!layout.interlaced) return pass_bytes(kWhole);
    uint64_t total = 0;
    for (const Pass& p : kAdam7) total += pass_bytes(p);
    return total;
}

std::string check_png_samples(const unsigned char* data, const PngLayout& layout) {
    const uint64_t needed = png_filtered_bytes(layout);
    const std::string declared =
        std::to_string(layout.width) + " × " + std::to_string(layout.height) + " texels";
    Inflater inflater;
    z_stream& z = inflater.stream;
    RowWalker rows(layout);
    constexpr size_t kPiece = size_t(1) << 16;
    std::vector<unsigned char> piece(kPiece);
    uint64_t inflated = 0;
    bool ended = false;
    for (size_t k = 0; k < layout.idat.size() && !ended; ++k) {
        z.next_in = const_cast<unsigned char*>(data + layout.idat[k].first);
        z.avail_in = uInt(layout.idat[k].second);
        do {
            z.next_out = piece.data();
            z.avail_out = uInt(kPiece);
            const int status = inflate(&z, Z_NO_FLUSH);
            if (status == Z_MEM_ERROR) throw std::bad_alloc();
            if (status == Z_DATA_ERROR || status == Z_NEED_DICT || status == Z_STREAM_ERROR) {
                const std::string what = z.msg ? z.msg : "invalid data";
                if (what == "incorrect data check") {
                    return "the PNG's image data fails its Adler-32 check (damaged IDAT data)";
                }
                return "the PNG's IDAT data is not a valid zlib stream: " + what;
            }
            const size_t produced = kPiece - z.avail_out;
            inflated += produced;
            if (inflated > needed) {
                // Refused at the first piece past the size, so that no more is inflated.
                return "the PNG's IDAT data inflates beyond the " + std::to_string(needed) +
                       " bytes its " + declared + " need";
            }
            const std::string why = rows.feed(piece.data(), produced);
            if (!why.empty()) return why;
            if (status == Z_STREAM_END) {
                ended = true;
                break;
            }
        } while (z.avail_out == 0 || z.avail_in > 0);
    }
    if (!ended) return "the PNG's IDAT data ends inside its zlib stream";
    if (inflated < needed) {
        return "the PNG's IDAT data inflates to " + std::to_string(inflated) + " bytes; its " +
               declared + " need " + std::to_string(needed);
    }
    return "";
}

}  // namespace mcrt
