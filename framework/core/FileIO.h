#pragma once
// The one way shadowlab reads an input file and writes a small output file.
//
// Reading: only regular files (a FIFO, a device such as /dev/zero, a socket or a directory is bad
// input, never a hang), opened without blocking and checked again on the open descriptor, read up
// to a size cap (a config or sweep is far below kMaxTextInputBytes; a larger file is bad input).
//
// Writing: the text goes to a temporary file beside the target, is flushed to disk (fsync, checked
// close) and renamed over the target only if that is a regular file or absent: a symbolic link, a
// device or a directory at the target is refused, and on any failure the temporary is removed, so a
// full disk never leaves a 0-byte or half-written file under the real name.
#include <cstddef>
#include <string>
#include <vector>

namespace shadowlab {

/// Cap for JSON inputs (configs, sweeps, summaries): 256 MiB.
constexpr size_t kMaxTextInputBytes = size_t(256) << 20;
/// Cap for binary inputs (glTF / GLB, cache files): 4 GiB.
constexpr size_t kMaxBinaryInputBytes = size_t(4) << 30;

/// The whole content of a regular file, at most `maxBytes`; InputError(path, "", cause) otherwise
/// ("cannot open file: No such file or directory", "is a FIFO, not a regular file", "is larger than ...").
std::string readInputFile(const std::string& path, size_t maxBytes = kMaxTextInputBytes);
std::vector<unsigned char> readInputFileBytes(const std::string& path, size_t maxBytes = kMaxBinaryInputBytes);

/// "a FIFO", "a directory", "a symbolic link", ... for messages; "" for a regular file or nothing there.
std::string nonRegularKind(const std::string& path, bool followLinks);

/// A path as echoed in a message: at most 160 characters, its start and its end (which names the
/// file or folder) kept around "...", so an absurd path stays one readable line.
std::string shortPath(const std::string& path);

/// Writes `text` to `path` atomically (see above). RuntimeError on an I/O failure; InputError when
/// the target is not a regular file (the caller named a place that cannot hold a file).
void writeFileAtomic(const std::string& path, const std::string& text);

/// Whether the disk holding `dir` has less than 1 MiB left: a child process that wrote nothing (the
/// plotters) failed for a full disk, which is said as such rather than as an empty reason.
bool diskNearlyFull(const std::string& dir);

} // namespace shadowlab
