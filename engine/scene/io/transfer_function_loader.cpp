#include "engine/scene/io/transfer_function_loader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/core/text_file.h"

namespace strata {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& file, const std::string& field,
                       const std::string& reason) {
  throw Error(file + ": " + (field.empty() ? "" : field + ": ") + reason);
}

std::string child(const std::string& field, const std::string& key) {
  return field.empty() ? key : field + "." + key;
}

std::string element(const std::string& field, size_t index) {
  return field + "[" + std::to_string(index) + "]";
}

float unit_number(const json& value, const std::string& file, const std::string& field) {
  if (!value.is_number()) fail(file, field, "expected a number in [0, 1]");
  const double v = value.get<double>();
  if (!(v >= 0.0 && v <= 1.0))
    fail(file, field, "expected a number in [0, 1], got " + value.dump());
  return static_cast<float>(v);
}

TransferFunction::Stop stop_from_json(const json& stop, const std::string& file,
                                      const std::string& field, bool in_values) {
  if (!stop.is_object())
    fail(file, field, "expected an object {\"position\": ..., \"color\": ...}");
  for (const auto& [key, value] : stop.items()) {
    if (key != "position" && key != "color") {
      fail(file, field, "unknown key '" + key + "' (expected position, color)");
    }
  }
  if (!stop.contains("position")) fail(file, field, "missing key 'position'");
  if (!stop.contains("color")) fail(file, field, "missing key 'color'");
  TransferFunction::Stop result;
  if (in_values) {
    const json& position = stop["position"];
    const double v = position.is_number() ? position.get<double>() : NAN;
    if (!(std::abs(v) <= 1e9))
      fail(file, child(field, "position"), "expected a value of the volume (|v| <= 1e9)");
    result.position = static_cast<float>(v);
  } else {
    result.position = unit_number(stop["position"], file, child(field, "position"));
  }
  const json& color = stop["color"];
  const std::string color_field = child(field, "color");
  if (!color.is_array() || color.size() != 4) {
    fail(file, color_field, "expected 4 numbers [r, g, b, a] in [0, 1]");
  }
  for (int c = 0; c < 4; ++c) result.color[c] = unit_number(color[c], file, color_field);
  return result;
}

bool parse_double(const char* text, double& value) {
  const char* end = text + std::char_traits<char>::length(text);
  const auto [rest, error] = std::from_chars(text, end, value);
  return error == std::errc() && rest == end && rest != text;
}

// Channels are integers 0..255. One published file has a="0.01" and a="0.9": the thesis program
// read those with QString::toInt, which gives 0; reading them as numbers on the 0..255 scale
// differs from that by less than one step and keeps what the file says.
float gra_channel(const pugi::xml_node& color, const char* name, const std::string& file,
                  const std::string& field) {
  const pugi::xml_attribute attribute = color.attribute(name);
  if (!attribute) fail(file, field, std::string("missing attribute '") + name + "'");
  double value = -1.0;
  // (written so that NaN, which compares false with everything, fails too)
  if (!parse_double(attribute.value(), value) || !(value >= 0.0 && value <= 255.0)) {
    fail(file, field,
         std::string("attribute '") + name + "' is '" + attribute.value() +
             "', expected a number 0..255");
  }
  return static_cast<float>(value) / 255.0f;
}

TransferFunction::Stop gra_stop(const pugi::xml_node& node, const std::string& file,
                                const std::string& field) {
  TransferFunction::Stop stop;
  const pugi::xml_attribute position = node.attribute("position");
  if (!position) fail(file, field, "missing attribute 'position'");
  double value = 0.0;
  if (!parse_double(position.value(), value) || !(value >= 0.0 && value <= 1.0)) {
    fail(file, field,
         std::string("position is '") + position.value() + "', expected a number in [0, 1]");
  }
  stop.position = static_cast<float>(value);
  const pugi::xml_node color = node.child("colorData");
  if (!color) fail(file, field, "missing <colorData>");
  const std::string color_field = child(field, "colorData");
  stop.color = glm::vec4(
      gra_channel(color, "r", file, color_field), gra_channel(color, "g", file, color_field),
      gra_channel(color, "b", file, color_field), gra_channel(color, "a", file, color_field));
  return stop;
}

}  // namespace

TransferFunction transfer_function_from_json(const json& object, const std::string& file,
                                             const std::string& field) {
  if (!object.is_object()) fail(file, field, "expected a transfer-function object");
  for (const auto& [key, value] : object.items()) {
    if (key != "strata_transfer_function" && key != "name" && key != "units" && key != "stops") {
      fail(file, field,
           "unknown key '" + key + "' (expected strata_transfer_function, name, units, stops)");
    }
  }
  if (object.contains("strata_transfer_function") && object["strata_transfer_function"] != 1) {
    fail(file, child(field, "strata_transfer_function"),
         "version " + json_for_message(object["strata_transfer_function"]) +
             " is not supported (this strata reads version 1)");
  }
  TransferFunction tf;
  if (object.contains("name")) {
    if (!object["name"].is_string()) fail(file, child(field, "name"), "expected a string");
    tf.name = object["name"].get<std::string>();
  }
  if (object.contains("units")) {
    const json& units = object["units"];
    if (!units.is_string() || (units != "HU" && units != "raw" && units != "range"))
      fail(file, child(field, "units"),
           "expected \"HU\" or \"raw\" (positions in the volume's values) or \"range\" (0..1 of "
           "its value range, the default)");
    if (units != "range") tf.units = units.get<std::string>();
  }
  const std::string stops_field = child(field, "stops");
  if (!object.contains("stops")) fail(file, field, "missing key 'stops'");
  const json& stops = object["stops"];
  if (!stops.is_array() || stops.empty()) fail(file, stops_field, "expected a non-empty array");
  for (size_t i = 0; i < stops.size(); ++i) {
    tf.stops.push_back(stop_from_json(stops[i], file, element(stops_field, i), !tf.units.empty()));
    // Sorted stops are part of the format: an unsorted file is most likely a typo.
    if (i > 0 && tf.stops[i].position < tf.stops[i - 1].position) {
      fail(file, child(element(stops_field, i), "position"),
           "stops must be sorted by position (this one is before the previous one)");
    }
  }
  return tf;
}

nlohmann::ordered_json transfer_function_to_json(const TransferFunction& tf) {
  nlohmann::ordered_json stops = nlohmann::ordered_json::array();
  for (const TransferFunction::Stop& stop : tf.stops) {
    nlohmann::ordered_json color = nlohmann::ordered_json::array();
    for (int c = 0; c < 4; ++c) color.push_back(shortest_double(stop.color[c]));
    stops.push_back({{"position", shortest_double(stop.position)}, {"color", color}});
  }
  nlohmann::ordered_json out = {{"strata_transfer_function", 1}, {"name", tf.name}};
  if (!tf.units.empty()) out["units"] = tf.units;
  out["stops"] = stops;
  return out;
}

TransferFunction load_transfer_function_json(const std::filesystem::path& path) {
  const std::string file = path.string();
  const json object = read_json_file(path);
  if (!object.is_object() || !object.contains("strata_transfer_function")) {
    fail(file, "", "not a strata transfer function (no \"strata_transfer_function\": 1)");
  }
  TransferFunction tf = transfer_function_from_json(object, file, "");
  if (tf.name.empty()) tf.name = path.stem().string();
  tf.source = path;
  return tf;
}

TransferFunction load_transfer_function_gra(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::string text = read_text_file(path);
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(text.data(), text.size());
  if (!parsed) {
    fail(file, "",
         std::string("XML error at ") + text_position(text, parsed.offset) + ": " +
             parsed.description());
  }
  const pugi::xml_node gradient = document.child("gradientData");
  if (!gradient) fail(file, "", "not a Qt gradient file (no <gradientData> element)");
  TransferFunction tf;
  tf.name = path.stem().string();
  tf.source = path;
  size_t index = 0;
  for (const pugi::xml_node stop : gradient.children("stopData")) {
    tf.stops.push_back(gra_stop(stop, file, element("stopData", index++)));
  }
  if (tf.stops.empty()) fail(file, "gradientData", "no <stopData> stops");
  // Qt sorts a gradient's stops when it sets them; a hand-edited file may not be sorted.
  std::stable_sort(tf.stops.begin(), tf.stops.end(),
                   [](const auto& a, const auto& b) { return a.position < b.position; });
  return tf;
}

TransferFunction load_transfer_function(const std::filesystem::path& path) {
  const std::string extension = path.extension().string();
  if (extension == ".json") return load_transfer_function_json(path);
  if (extension == ".gra") return load_transfer_function_gra(path);
  fail(path.string(), "",
       "unknown transfer-function format '" + extension + "' (expected .json or .gra)");
}

void write_transfer_function_json(const std::filesystem::path& path, const TransferFunction& tf) {
  write_text_file(path, transfer_function_to_json(tf).dump(2) + '\n');
}

bool is_transfer_function_file(const std::filesystem::path& path) {
  if (path.extension() == ".gra") return true;
  if (path.extension() != ".json") return false;
  try {
    const json object = json::parse(read_text_file(path));
    return object.is_object() && object.contains("strata_transfer_function");
  } catch (const std::exception&) {
    return false;  // the scene loader reports what is wrong with it
  }
}

}  // namespace strata
