// Non-finite pixels: a radiance sum that overflowed single precision (an Inf mean, or an Inf
// variance from the sum of squares) must never reach a file (ROBUSTNESS.md "Values that
// overflow").
#pragma once

#include <cstdint>

#include "image/image.h"

namespace mcrt {

// Pixels with any non-finite mean or variance channel.
uint64_t nonfinite_pixels(const Image& image);

}  // namespace mcrt
