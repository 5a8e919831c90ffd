#pragma once
// What the binary was built from, recorded in every summary.json (`build`) so that results kept
// across commits (`shadowlab history`) say which commit each came from. Generated at build time by
// cmake/BuildInfo.cmake.

namespace shadowlab {

/// The git commit of the sources (40 hex digits), or "unknown" outside a git checkout.
const char* buildCommit();
/// Whether tracked files had uncommitted changes when the binary was built.
bool buildDirty();

} // namespace shadowlab
