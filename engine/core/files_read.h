// The files this process has read, so that a command can refuse an output that would replace one
// of them (`render scene.json --layout scene.json`). Every reader checks its input with
// check_input_file (text_file.h), which records it here; loaders that read in a child process
// (DICOM, meshes) have their files or folders recorded by the parent. Files are compared by
// identity (device and inode), so another spelling, `./`, a symlink or a hard link to an input is
// that input too.
#pragma once

#include <filesystem>
#include <optional>

namespace strata {

// Records `path`, a file or a folder read whole (a DICOM series), as read. A path that cannot be
// examined is skipped: nothing was read from it.
void record_file_read(const std::filesystem::path& path);

// The input that writing `path` would replace, as it was recorded: a file read, or the folder
// read whole that holds the existing file `path`. Nothing for a path that does not exist yet.
std::optional<std::filesystem::path> input_replaced_by(const std::filesystem::path& path);

}  // namespace strata
