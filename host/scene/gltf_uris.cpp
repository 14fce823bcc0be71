#include "scene/gltf_uris.h"

#include <cctype>
#include <nlohmann/json.hpp>

#include "common/error.h"

namespace mcrt::gltf {

namespace {

using nlohmann::json;

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// tinygltf 2.7's decoding of a uri (dlib's urldecode, tiny_gltf.h): '+' as a space, "%XY" as a
// byte (a non-hex digit as 0). Reproduced only to know the path its callbacks will be given.
std::string tinygltf_decode(const std::string& uri) {
    std::string result;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') {
            result += ' ';
        } else if (uri[i] == '%' && uri.size() > i + 2) {
            const int hi = hex_value(uri[i + 1]), lo = hex_value(uri[i + 2]);
            result += static_cast<char>(((hi < 0 ? 0 : hi) << 4) | (lo < 0 ? 0 : lo));
            i += 2;
        } else {
            result += uri[i];
        }
    }
    return result;
}

// tinygltf's JoinPath.
std::string join_path(const std::string& dir, const std::string& file) {
    if (dir.empty()) return file;
    return dir.back() == '/' ? dir + file : dir + "/" + file;
}

// A decoded reference as a file path: an absolute path as it is, a relative one in `base_dir`.
std::string resolve(const std::string& base_dir, const std::string& decoded) {
    return !decoded.empty() && decoded[0] == '/' ? decoded : join_path(base_dir, decoded);
}

void scan_array(const std::string& name, const json& root, const char* key, bool buffers,
                const std::string& base_dir, std::map<std::string, UriTarget>& targets) {
    const auto list = root.find(key);
    if (list == root.end() || !list->is_array()) return;
    for (size_t i = 0; i < list->size(); ++i) {
        const json& item = (*list)[i];
        if (!item.is_object()) continue;
        const auto uri = item.find("uri");
        if (uri == item.end() || !uri->is_string()) continue;
        UriTarget target;
        target.element = std::string(buffers ? "buffer " : "image ") + std::to_string(i);
        target.uri = uri->get<std::string>();
        const std::string scheme = uri_scheme(target.uri);
        if (scheme == "data") continue;  // embedded: tinygltf decodes it
        if (!scheme.empty()) {
            throw InputError(name + ": " + target.element + ": uri '" + target.uri + "': the " +
                             scheme +
                             " scheme is not supported (only relative paths, absolute paths and "
                             "data: URIs)");
        }
        target.path = resolve(base_dir, percent_decode(target.uri));
        target.buffer = buffers;
        if (buffers) {
            const auto length = item.find("byteLength");
            if (length == item.end() || !length->is_number_unsigned())
                continue;  // tinygltf refuses
            target.byte_length = length->get<uint64_t>();
        }
        targets.emplace(tinygltf_path(base_dir, target.uri), std::move(target));
    }
}

}  // namespace

std::string tinygltf_path(const std::string& base_dir, const std::string& uri) {
    return resolve(base_dir, tinygltf_decode(uri));
}

std::string percent_decode(const std::string& uri) {
    std::string result;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex_value(uri[i + 1]) >= 0 &&
            hex_value(uri[i + 2]) >= 0) {
            result += static_cast<char>(hex_value(uri[i + 1]) * 16 + hex_value(uri[i + 2]));
            i += 2;
        } else {
            result += uri[i];
        }
    }
    return result;
}

std::string uri_scheme(const std::string& uri) {
    if (uri.empty() || !std::isalpha(static_cast<unsigned char>(uri[0]))) return {};
    for (size_t i = 1; i < uri.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(uri[i]);
        if (c == ':') {
            std::string scheme = uri.substr(0, i);
            for (char& s : scheme)
                s = static_cast<char>(std::tolower(static_cast<unsigned char>(s)));
            return scheme;
        }
        if (!std::isalnum(c) && c != '+' && c != '-' && c != '.') return {};
    }
    return {};
}

std::map<std::string, UriTarget> scan_uris(const std::string& name, const char* json_text,
                                           size_t size, const std::string& base_dir) {
    std::map<std::string, UriTarget> targets;
    const json root = json::parse(json_text, json_text + size, nullptr, false);
    if (!root.is_object()) return targets;
    scan_array(name, root, "buffers", true, base_dir, targets);
    scan_array(name, root, "images", false, base_dir, targets);
    return targets;
}

}  // namespace mcrt::gltf
