// Whole text files for the parsers, and positions inside them for error messages.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace strata {

// The file's bytes; Error "<file>: no such file" or "<file>: cannot read the file".
std::string read_text_file(const std::filesystem::path& path);
// Writes `text` to `path` (replacing it); an Error naming the path when it cannot.
void write_text_file(const std::filesystem::path& path, const std::string& text);

// "line L, column C (offset O)" of a byte offset into text (as XML parsers report offsets).
std::string text_position(const std::string& text, std::ptrdiff_t offset);

}  // namespace strata
