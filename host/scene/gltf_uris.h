// What the uris of a glTF file's buffers and images name, read from its JSON before tinygltf
// reads any file ("URIs": RFC 3986 references, relative ones resolved against the file): the
// file each names, and the size it may have, so that nothing is read beyond what is declared.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace mcrt::gltf {

// One external file a uri names.
struct UriTarget {
    std::string element;       // "buffer 0", "image 2"
    std::string uri;           // as written in the file
    std::string path;          // the file it names: percent-decoded, resolved
    bool buffer = false;       // a buffer, whose byteLength is known
    uint64_t byte_length = 0;  // buffers: the declared byteLength
};

// The path that tinygltf hands to its file callbacks for `uri` (joined to `base_dir` after its
// own decoding, absolute paths kept), which is the key of the map below.
std::string tinygltf_path(const std::string& base_dir, const std::string& uri);

// RFC 3986 §2.1 percent-decoding ("a%20b.bin" names "a b.bin"; '+' stays '+').
std::string percent_decode(const std::string& uri);

// The scheme of `uri` in lower case (RFC 3986 §3.1: ALPHA *( ALPHA / DIGIT / "+" / "-" / "." )
// followed by ':'), or "" for a relative reference or an absolute path.
std::string uri_scheme(const std::string& uri);

// Every buffer and image uri of the glTF JSON text [json, json + size) that names a file, keyed
// by tinygltf_path(base_dir, uri). Throws InputError "<name>: buffer 0: uri 'http://x/a.bin':
// the http scheme is not supported (...)" for a uri with any scheme but data:. JSON that does
// not parse yields nothing (tinygltf then names the error).
std::map<std::string, UriTarget> scan_uris(const std::string& name, const char* json, size_t size,
                                           const std::string& base_dir);

}  // namespace mcrt::gltf
