// Bounds on radiance values, so that nothing a render sums can overflow single precision
// (ROBUSTNESS.md "Values that overflow"). A chunk of 16 samples sums squares in float on the
// device: 16 · L² ≤ FLT_MAX needs L ≤ 4.6e18; the bound leaves three orders of magnitude for
// the throughput and pdf factors of the estimators. The sun's radiance is about 1.6e9 W/(sr·m²).
#pragma once

namespace mcrt {

constexpr double kMaxRadiance = 1e15;  // each component of Le (emission) and of --sky

}  // namespace mcrt
