#pragma once
// Files that are never lost or half-written: the text goes to a temporary file in the target's
// folder, is flushed to disk (fsync), and is renamed over the target (rename(2) is atomic on one
// file system). A write killed midway leaves the old file as it was; a failed write removes its
// temporary file. A symbolic link is followed (the file it names is replaced, the link stays);
// a FIFO or a device (/dev/null, /dev/stdout) is written into, as a shell redirection would: a
// rename over it would replace it. Every writer of the project (shapes, trajectories, results,
// rows, tables, pictures) uses it.
//
//   if (std::string error = WriteFileAtomically("out/result.json", text); !error.empty())
//     throw MyError(error);   // "out/result.json: cannot write (No space left on device)"
#include <string>

namespace pushgraph::geometry {

/// Writes `content` to `path` atomically; returns an empty string on success, else a message
/// naming the path and the system's reason (the caller throws its module's error type).
std::string WriteFileAtomically(const std::string& path, const std::string& content);

}  // namespace pushgraph::geometry
