#pragma once
// What the mutation corpus (FuzzCorpusTest) and the libFuzzer targets (tests/fuzz/) run on each
// input: the real loaders, with the scene's triangle budget lowered so that a case stays small.
// Both throw InputError for bad input; anything else escaping is a bug.
#include <string>

namespace shadowlab::fuzz {

/// The triangle budget a fuzzed scene may use (the default is 20 M).
constexpr int kMaxTriangles = 200'000;

/// Parses a config text as `shadowlab validate` does (scene loaded), under the budget above; `file`
/// names it in errors and anchors relative paths. Returns the scene's triangle count.
size_t loadConfigText(const std::string& text, const std::string& file);
/// Loads a .gltf/.glb file under the budget above; returns its triangle count.
size_t loadSceneFile(const std::string& path);

} // namespace shadowlab::fuzz
