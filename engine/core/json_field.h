// Where a value sits in a JSON file, for errors that name it ("scene.json: volumes[0].transform:
// expected 16 numbers"), the key lookups every JSON reader of strata makes, and the numbers its
// JSON writers write.
#pragma once

#include <charconv>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/text_file.h"

namespace strata {

struct JsonField {
  const std::string& file;
  std::string path;

  JsonField operator/(const std::string& key) const {
    return {file, path.empty() ? key : path + "." + key};
  }
  JsonField operator[](size_t index) const {
    return {file, path + "[" + std::to_string(index) + "]"};
  }
  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(file + ": " + (path.empty() ? "" : path + ": ") + reason);
  }
  // Runs a loader for the file this field names and puts the field before its error.
  template <typename F>
  auto wrap(F&& load) const {
    try {
      return load();
    } catch (const Error& e) {
      fail(e.what());
    }
  }
};

// The member `key` of `object`, or none.
inline const nlohmann::json* optional(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

// The member `key` of `object`; an error naming the field when it is missing.
inline const nlohmann::json& required(const nlohmann::json& object, const JsonField& field,
                                      const char* key) {
  const nlohmann::json* value = optional(object, key);
  if (!value) field.fail(std::string("missing key '") + key + "'");
  return *value;
}

// `count` finite numbers in an array; an error naming the field otherwise.
inline std::vector<double> json_numbers(const nlohmann::json& value, const JsonField& field,
                                        size_t count) {
  const std::string expected = "expected " + std::to_string(count) + " numbers";
  if (!value.is_array() || value.size() != count) field.fail(expected);
  std::vector<double> result;
  for (const nlohmann::json& v : value) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) field.fail(expected);
    result.push_back(v.get<double>());
  }
  return result;
}

// A value as an error message shows it: a number, string, bool or null as JSON, an array or an
// object as "[...]" or "{...}", since dump() recurses once per level of nesting and a deeply
// nested value ("[[[[...]]]]") overflowed the stack.
inline std::string json_for_message(const nlohmann::json& value) {
  if (value.is_array()) return "[...]";
  if (value.is_object()) return "{...}";
  return value.dump();
}

// The JSON document in `path`. A syntax error is one Error "<file>: parse error at line L,
// column C: ..." (nlohmann's message without its "[json.exception.parse_error.101] " prefix).
// nlohmann reports a number too large for a double ("1e400") as out_of_range, not as a parse
// error, so every exception of its own is caught.
inline nlohmann::json read_json_file(const std::filesystem::path& path) {
  try {
    return nlohmann::json::parse(read_text_file(path));
  } catch (const nlohmann::json::exception& e) {
    const std::string what = e.what();
    const size_t end = what.find("] ");
    throw Error(path.string() + ": " + (end == std::string::npos ? what : what.substr(end + 2)));
  }
}

// The JSON value of a float written with the fewest digits that read back as the same float
// (0.1f is written 0.1, not 0.10000000149011612).
inline double shortest_double(float value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  double shortest = value;
  std::from_chars(text, result.ptr, shortest);
  return shortest;
}

}  // namespace strata
