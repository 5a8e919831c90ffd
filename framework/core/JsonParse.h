#pragma once
// Strict JSON parsing for every file and value a user hands us (configs, --set values, sweep
// files, the JSON of glTF files).
//
// nlohmann's DOM parser accepts inputs that later hurt: nesting tens of thousands deep (copying,
// printing or tinygltf's recursive reader then overflow the stack), duplicate keys (the last one
// silently wins), and numbers that overflow a double ("1e999", reported without a JSON path).
// parseJson() builds the same DOM through a SAX handler that enforces limits while it reads, so a
// hostile input is rejected before anything large or deep exists, with the JSON path of the fault.
#include "framework/core/Error.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>

namespace shadowlab {

using Json = nlohmann::json;

struct JsonLimits {
    int maxDepth = 64;                ///< nesting of arrays and objects; configs need < 30 (8 nested grids)
    size_t maxValues = 2'000'000;     ///< values of any kind, containers included
    bool rejectDuplicateKeys = true;  ///< configs are strict; glTF files in the wild sometimes repeat keys
};

/// Parses `text`; throws InputError(file, JSON path, cause) when it is not valid JSON or breaks a limit.
Json parseJson(const std::string& text, const std::string& file, const JsonLimits& limits = {});

/// `value` printed as JSON, cut to about `maxChars` characters ("..." marks the cut), for error
/// messages: an error line must stay one short line even when the value is a million numbers long.
std::string shortDump(const Json& value, size_t maxChars = 60);

} // namespace shadowlab
