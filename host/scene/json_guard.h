// A bound on JSON nesting checked before tinygltf parses the text: its recursive conversion
// overflows the call stack near 20,000 levels (ROBUSTNESS.md "Inputs that hang or crash the
// loader").
#pragma once

#include <cstddef>
#include <string>

namespace mcrt {

// Deepest nesting any glTF file needs is a few tens of levels (extras and extensions add some).
constexpr size_t kMaxJsonNesting = 512;

// The deepest nesting of arrays and objects in the JSON text [data, data + size), brackets inside
// strings (with their escapes) not counted; stops counting once `limit` is passed.
size_t json_nesting_depth(const char* data, size_t size, size_t limit = kMaxJsonNesting);

// The JSON chunk of a GLB container ("GLB File Format Specification": 12-byte header, then chunk
// length, type "JSON", data), or false when the bytes are too short to hold one (tinygltf then
// reports the format error itself).
bool glb_json_chunk(const unsigned char* data, size_t size, const char** json, size_t* json_size);

// Throws InputError "<name>: JSON nested deeper than 512 levels" when the glTF bytes (.gltf text
// or GLB) nest deeper than kMaxJsonNesting.
void check_json_nesting(const std::string& name, const unsigned char* data, size_t size, bool glb);

}  // namespace mcrt
