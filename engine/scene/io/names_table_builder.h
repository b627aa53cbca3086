// What the names-table readers share (names_table.cpp, nifti_extensions.cpp): the checks every
// entry passes and the form of their errors. Not part of the engine's API.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "engine/scene/segmentation.h"

namespace strata::names_table {

// Throws Error("<file>: <where>: <reason>"), or "<file>: <reason>" when `where` is empty.
[[noreturn]] void fail(const std::filesystem::path& file, const std::string& where,
                       const std::string& reason);

// A whole decimal integer (a leading '+' allowed); none otherwise.
std::optional<int64_t> parse_integer(std::string_view text);

// The entries of one table in file order. Each value is checked to be in 0..kMaxRegionValue and
// named once, each name to be non-empty UTF-8 text; `where` ("line 4", "labels.'liver'") places
// the entry in errors.
struct TableBuilder {
  const std::filesystem::path& file;
  NamesTable table;
  std::map<int, std::string> where_first;

  void add(const std::string& where, int64_t value, std::string name,
           std::optional<glm::vec3> colour = {});
  // The table; an Error when it has no entries.
  NamesTable finish(std::string format);
};

}  // namespace strata::names_table
