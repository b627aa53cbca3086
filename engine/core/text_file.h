// Whole text files for the parsers, and positions inside them for error messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace strata {

// Text files (scenes, transfer functions, label lists, scripts) are read whole; none of strata's
// is near this size, and a limit means a wrong or hostile file cannot take the machine's memory.
inline constexpr uint64_t kMaxTextFileBytes = uint64_t{64} << 20;

// The size of a file strata is about to read, after checking that it is one: Error "<file>: no
// such file", "<file>: is a folder, not a file" or "<file>: is not a regular file (a FIFO, device
// or socket)". Reading a FIFO or a device could block forever or never end, so every reader
// checks its inputs here first; each is recorded as read (files_read.h).
uint64_t check_input_file(const std::filesystem::path& path);

// The file's bytes after check_input_file and a check against max_bytes ("<file>: is N MiB; ...
// at most M MiB"); Error "<file>: cannot read the file" when reading fails.
std::string read_file_bytes(const std::filesystem::path& path,
                            uint64_t max_bytes = kMaxTextFileBytes);
// read_file_bytes for text: a NUL byte is an Error naming its line and column (parsers would
// stop there and silently drop the rest of the file).
std::string read_text_file(const std::filesystem::path& path,
                           uint64_t max_bytes = kMaxTextFileBytes);
// Writes `text` to `path` whole or not at all (atomic_file.h); an Error naming the path when it
// cannot.
void write_text_file(const std::filesystem::path& path, const std::string& text);

// "line L, column C (offset O)" of a byte offset into text (as XML parsers report offsets).
std::string text_position(const std::string& text, std::ptrdiff_t offset);

}  // namespace strata
