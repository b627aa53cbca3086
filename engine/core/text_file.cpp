#include "engine/core/text_file.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>

#include "engine/core/atomic_file.h"
#include "engine/core/error.h"
#include "engine/core/files_read.h"

namespace strata {

namespace {

std::string mebibytes(uint64_t bytes) {
  std::ostringstream text;
  text.precision(bytes < (uint64_t{10} << 20) ? 2 : 0);
  text << std::fixed << double(bytes) / double(1 << 20) << " MiB";
  return text.str();
}

}  // namespace

uint64_t check_input_file(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);  // follows links: the target counts
  if (status.type() == fs::file_type::not_found) throw Error(path.string() + ": no such file");
  if (ec) throw Error(path.string() + ": cannot read the file (" + ec.message() + ")");
  if (status.type() == fs::file_type::directory)
    throw Error(path.string() + ": is a folder, not a file");
  if (status.type() != fs::file_type::regular)
    throw Error(path.string() +
                ": is not a regular file (a FIFO, device or socket); strata reads "
                "only files");
  const uint64_t size = fs::file_size(path, ec);
  if (ec) throw Error(path.string() + ": cannot read the file (" + ec.message() + ")");
  record_file_read(path);  // (no output of the command may replace it: files_read.h)
  return size;
}

std::string read_file_bytes(const std::filesystem::path& path, uint64_t max_bytes) {
  const uint64_t size = check_input_file(path);
  const auto too_big = [&](const std::string& size_text) {
    return Error(path.string() + ": is " + size_text + "; files of this kind may have at most " +
                 mebibytes(max_bytes));
  };
  if (size > max_bytes) throw too_big(mebibytes(size));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot read the file");
  // Read at most one byte past the limit: the file may have grown since its size was taken.
  std::string text(size_t(std::min<uint64_t>(size, max_bytes) + 1), '\0');
  in.read(text.data(), std::streamsize(text.size()));
  if (in.bad()) throw Error(path.string() + ": cannot read the file");
  text.resize(size_t(in.gcount()));
  if (text.size() > max_bytes) throw too_big("over " + mebibytes(max_bytes));
  return text;
}

std::string read_text_file(const std::filesystem::path& path, uint64_t max_bytes) {
  std::string text = read_file_bytes(path, max_bytes);
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    throw Error(path.string() + ": a NUL byte at " + text_position(text, std::ptrdiff_t(nul)) +
                ": not a text file");
  return text;
}

void write_text_file(const std::filesystem::path& path, const std::string& text) {
  write_file_atomically(path, text);
}

std::string text_position(const std::string& text, std::ptrdiff_t offset) {
  const auto upto =
      text.begin() + std::clamp<std::ptrdiff_t>(offset, 0, std::ptrdiff_t(text.size()));
  const auto line = std::count(text.begin(), upto, '\n') + 1;
  const auto line_start = std::find(std::make_reverse_iterator(upto), text.rend(), '\n').base();
  return "line " + std::to_string(line) + ", column " + std::to_string(upto - line_start + 1) +
         " (offset " + std::to_string(offset) + ")";
}

}  // namespace strata
