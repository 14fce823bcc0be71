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
// Decoded texture images (gltf_images.cpp), checked from each image's header before any texel is
// allocated: at most 16384 texels per side (1 GiB as RGBA; the textured sample scenes stop at
// 2048), and 2^30 texels (4 GiB) over all the images a scene's materials use.
constexpr unsigned kMaxImageSide = 16384;
constexpr unsigned long long kMaxImageTexels = 1ull << 30;
// What the decoders hold while images decode, estimated from each header (gltf_images.cpp
// decode_bytes): images are decoded at once on several threads only while their estimates sum to
// at most this; an image whose estimate is larger is decoded alone.
constexpr unsigned long long kMaxDecodingBytes = 4ull << 30;
// Encoded image files, whose size nothing declares, checked before they are read (tinygltf reads
// every image file, used or not): each at most 1 GiB, what the largest image allowed above holds
// as 8-bit RGBA, and 4 GiB over all of a scene's image files.
constexpr unsigned long long kMaxImageFileBytes = 1ull << 30;
constexpr unsigned long long kMaxImageFilesBytes = 4ull << 30;

}  // namespace mcrt::gltf
