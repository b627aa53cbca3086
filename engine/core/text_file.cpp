#include "engine/core/text_file.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>

#include "engine/core/error.h"

namespace strata {

std::string read_text_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path.string() + ": no such file");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw Error(path.string() + ": cannot read the file");
  return std::move(text).str();
}

void write_text_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.flush()) throw Error(path.string() + ": cannot write the file");
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
