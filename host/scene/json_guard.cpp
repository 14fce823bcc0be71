#include "scene/json_guard.h"

#include <cstdint>
#include <cstring>

#include "common/error.h"

namespace mcrt {

size_t json_nesting_depth(const char* data, size_t size, size_t limit) {
    size_t depth = 0, deepest = 0;
    bool in_string = false;
    for (size_t i = 0; i < size; ++i) {
        const char c = data[i];
        if (in_string) {
            if (c == '\\') {
                ++i;  // the escaped character cannot end the string
            } else if (c == '"') {
                in_string = false;
            }
            continue;
        }
        if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > deepest) deepest = depth;
            if (deepest > limit) return deepest;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

bool glb_json_chunk(const unsigned char* data, size_t size, const char** json, size_t* json_size) {
    if (size < 20) return false;
    uint32_t length = 0;
    std::memcpy(&length, data + 12, 4);  // little-endian, as every platform mcrt runs on
    const size_t available = size - 20;
    *json = reinterpret_cast<const char*>(data + 20);
    *json_size = length < available ? length : available;
    return true;
}

void check_json_nesting(const std::string& name, const unsigned char* data, size_t size, bool glb) {
    const char* json = reinterpret_cast<const char*>(data);
    size_t json_size = size;
    if (glb && !glb_json_chunk(data, size, &json, &json_size)) return;
    if (json_nesting_depth(json, json_size) > kMaxJsonNesting) {
        throw InputError(name + ": JSON nested deeper than " + std::to_string(kMaxJsonNesting) +
                         " levels");
    }
}

}  // namespace mcrt
