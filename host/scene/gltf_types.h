// JSON types of the glTF properties mcrt reads, checked on the text itself: tinygltf silently
// ignores a known property of the wrong type ("mesh": "0" reads as no mesh), which would render
// a different scene without a word (ROBUSTNESS.md "Silently wrong input").
#pragma once

#include <cstddef>
#include <string>

namespace mcrt {

// Throws InputError "<name>: nodes[2].mesh: expected an integer, found a string". Text that is
// not JSON is left to tinygltf's parser, which names the error.
void check_gltf_property_types(const std::string& name, const unsigned char* json, size_t size);

}  // namespace mcrt
