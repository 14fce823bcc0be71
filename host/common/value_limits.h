// Bounds on radiance values (ROBUSTNESS.md "Values that overflow"). Samples are floats: an
// estimate is L_e times throughput and 1/pdf factors, so the bound leaves eight orders of
// magnitude below FLT_MAX (3.4e38) for those; a sample that still overflows is counted as
// non-finite. The device sums samples shifted and scaled by a power of two (ChunkSums), so no sum
// or square overflows below FLT_MAX. The sun's radiance is about 1.6e9 W/(sr·m²).
#pragma once

namespace mcrt {

constexpr double kMaxRadiance = 1e30;  // each component of Le (emission) and of --sky

}  // namespace mcrt
