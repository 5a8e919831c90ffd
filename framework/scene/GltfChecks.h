#pragma once
// The glTF document checked before the reader (tinygltf) sees it: JSON types against the glTF 2.0
// schema, the version, what rigid triangles cannot show (skins, morph targets), node transforms,
// and what the reader refuses without a path or misreads. Every problem is an InputError naming
// its JSON path. Used by GltfLoader.cpp only.
#include "framework/core/JsonNode.h"

#include <cstddef>
#include <string>
#include <vector>

namespace shadowlab::gltf {

/// The largest buffer file read (what readInputFileBytes is given: a glTF byteLength is a uint32 in practice).
constexpr size_t kMaxBufferFileBytes = 0xFFFFFFF0u;

/// Every check of stages 1 and 2 on the parsed document; `binLength` is the GLB's binary chunk
/// length (0 for a .gltf).
void checkDocument(const Json& doc, const std::string& file, bool binary, size_t binLength);
/// The JSON chunk of a GLB container, with the header checked so nothing is read past the end.
std::string glbJson(const std::string& file, const std::vector<unsigned char>& bytes);
/// The GLB's binary chunk length (0 when it has none): what buffer 0 may take from it.
size_t glbBinLength(const std::vector<unsigned char>& bytes);
/// The reader's multi-line messages as one line.
std::string oneLine(const std::string& s);
/// JSON pointer escaping (RFC 6901), for keys such as attribute names that end up in error paths.
std::string escapeKey(const std::string& key);

} // namespace shadowlab::gltf
