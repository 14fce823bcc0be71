// Sanity limits of the glTF import: beyond them a file is treated as invalid rather than
// exhausting memory, all in one place so that every bound a file meets can be read together.
#pragma once

#include <cstddef>

namespace mcrt::gltf {

constexpr double kMaxCoordinate = 1e30;                 // any position component
constexpr size_t kMaxTriangles = size_t(1) << 26;       // after instancing
constexpr size_t kMaxNodeInstances = size_t(1) << 24;   // shared subtrees multiply
constexpr size_t kMaxZeroBasedCount = size_t(1) << 24;  // sparse accessor without data
constexpr size_t kMaxFileBytes = size_t(4) << 30;       // the scene file and each buffer
// Beyond this magnitude float traversal may lose triangles: a floor quad of half-size S seen by
// the bench camera renders for S ≤ 2e12, partly at 4e12, not at 7e12 (ROBUSTNESS.md "Silently
// wrong input"); the bound keeps a factor 200 of margin. Such scenes load with one warning.
constexpr double kWarnCoordinate = 1e10;

}  // namespace mcrt::gltf
