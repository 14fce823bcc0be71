#include "image/image_check.h"

#include <cmath>

namespace mcrt {

uint64_t nonfinite_pixels(const Image& image) {
    uint64_t count = 0;
    const size_t pixels = image.rgb.size() / 3;
    for (size_t p = 0; p < pixels; ++p) {
        bool finite = true;
        for (size_t c = 0; c < 3; ++c) {
            finite = finite && std::isfinite(image.rgb[3 * p + c]) &&
                     (image.variance.size() != image.rgb.size() ||
                      std::isfinite(image.variance[3 * p + c]));
        }
        count += finite ? 0 : 1;
    }
    return count;
}

}  // namespace mcrt
