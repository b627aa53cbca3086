#include "app/viewer_script.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "engine/core/error.h"
#include "engine/scene/fitted_camera.h"
#include "engine/scene/scene.h"
#include "engine/scene/transfer_function_presets.h"
#include "engine/scene/value_limits.h"

namespace strata::app {
namespace {

// A finite number in [lo, hi] (a whole one with `whole`), written as nothing else.
double number(const std::string& word, double lo, double hi, bool whole = false) {
  const char* begin = word.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  const bool inside = end == begin + word.size() && std::isfinite(v) && v >= lo && v <= hi &&
                      (!whole || v == std::floor(v));
  if (!inside) {
    throw Error("'" + word + "' is not " + (whole ? "a whole number" : "a number") + " in [" +
                value_limits::shown(lo) + ", " + value_limits::shown(hi) + "]");
  }
  return v;
}

void check_key(const std::string& name) {
  static const char* const named[] = {"left",   "right", "up",  "down",
                                      "escape", "f12",   "F12", "space"};
  for (const char* n : named) {
    if (name == n) return;
  }
  if (name.size() == 1 &&
      ((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= '0' && name[0] <= '9')))
    return;
  throw Error("no key '" + name + "' (a-z, 0-9, left, right, up, down, escape, f12, space)");
}

void check_button(const std::string& name) {
  if (name != "left" && name != "right" && name != "middle")
    throw Error("no mouse button '" + name + "' (left, right, middle)");
}

void check_view(const std::string& name) {
  if (!anatomical_view_named(name))
    throw Error("no view '" + name + "' (anterior, posterior, left, right, superior, inferior)");
}

void check_preset(const std::string& name) {
  std::string names;
  for (const TransferFunctionPreset& p : transfer_function_presets()) {
    if (name == p.name) return;
    names += std::string(names.empty() ? "" : ", ") + p.name;
  }
  throw Error("no transfer-function preset '" + name + "' (" + names + ")");
}

ScriptCommand command(const std::vector<std::string>& w) {
  const std::string& c = w[0];
  const auto need = [&](size_t n, const char* form) {
    if (w.size() != n) throw Error("'" + c + "' takes the form: " + form);
  };
  ScriptCommand out;
  if (c == "drag") {
    if (w.size() != 6 && !(w.size() == 7 && w[6] == "shift")) {
      throw Error("'drag' takes the form: drag left|right|middle X0 Y0 X1 Y1 [shift]");
    }
    out.op = ScriptOp::drag;
    check_button(w[1]);
    out.word = w[1];
    for (size_t i = 2; i < 6; ++i) {
      out.numbers.push_back(number(w[i], -kScriptMaxCoordinate, kScriptMaxCoordinate));
    }
    out.shift = w.size() == 7;
  } else if (c == "scroll") {
    need(2, "scroll TICKS");
    out.op = ScriptOp::scroll;
    out.numbers = {number(w[1], -kScriptMaxScroll, kScriptMaxScroll)};
  } else if (c == "key") {
    need(2, "key NAME");
    out.op = ScriptOp::key;
    check_key(w[1]);
    out.word = w[1];
  } else if (c == "view") {
    need(2, "view anterior|posterior|left|right|superior|inferior");
    out.op = ScriptOp::view;
    check_view(w[1]);
    out.word = w[1];
  } else if (c == "preset") {
    if (w.size() != 2 && w.size() != 3)
      throw Error("'preset' takes the form: preset NAME [VOLUME]");
    out.op = ScriptOp::preset;
    check_preset(w[1]);
    out.word = w[1];
    out.numbers = {w.size() == 3 ? number(w[2], 0.0, kScriptMaxVolume, true) : 0.0};
  } else if (c == "set") {
    need(3, "set PARAMETER VALUE");
    out.op = ScriptOp::set;
    out.word = w[1];
    out.value = w[2];
  } else if (c == "hide" || c == "show") {
    need(2, "hide|show LABEL_ID");
    out.op = c == "hide" ? ScriptOp::hide : ScriptOp::show;
    out.numbers = {number(w[1], 0.0, kScriptMaxLabelId, true)};
  } else if (c == "screenshot" || c == "capture") {
    need(2, c == "screenshot" ? "screenshot FILE.png" : "capture FILE.png");
    out.op = c == "screenshot" ? ScriptOp::screenshot : ScriptOp::capture;
    out.word = w[1];
  } else if (c == "layout" || c == "report") {
    need(2, c == "layout" ? "layout FILE.json" : "report FILE.json");
    out.op = c == "layout" ? ScriptOp::layout : ScriptOp::report;
    out.word = w[1];
  } else if (c == "record") {
    if (w.size() == 3 && w[1] == "start") {
      out.op = ScriptOp::record_start;
      out.word = w[2];
    } else if (w.size() == 2 && w[1] == "stop") {
      out.op = ScriptOp::record_stop;
    } else {
      throw Error("'record' takes the form: record start FILE.mp4 | record stop");
    }
  } else if (c == "frames") {
    need(2, "frames N");
    out.op = ScriptOp::frames;
    out.numbers = {number(w[1], 0.0, kScriptMaxFrames, true)};
  } else if (c == "sleep") {
    need(2, "sleep SECONDS");
    out.op = ScriptOp::sleep;
    out.numbers = {number(w[1], 0.0, kScriptMaxSleep)};
  } else if (c == "settle-limit") {
    need(2, "settle-limit SECONDS");
    out.op = ScriptOp::settle_limit;
    out.numbers = {number(w[1], 0.001, kScriptMaxSettle)};
  } else if (c == "save-position") {
    need(2, "save-position NAME");
    out.op = ScriptOp::save_position;
    out.word = w[1];
  } else if (c == "crop") {
    // (every volume's crop box in world mm, LPS; "crop off" removes it)
    if (w.size() == 2 && w[1] == "off") {
      out.op = ScriptOp::crop;
    } else {
      need(7, "crop X0 Y0 Z0 X1 Y1 Z1 | crop off");
      out.op = ScriptOp::crop;
      for (size_t i = 1; i < 7; ++i)
        out.numbers.push_back(number(w[i], -kScriptMaxWorld, kScriptMaxWorld));
      for (size_t a = 0; a < 3; ++a)
        if (!(out.numbers[a] < out.numbers[a + 3]))
          throw Error("'crop': each low corner value must be below the high one");
    }
  } else if (c == "clip") {
    // (every volume's clipping plane through P keeping the side N points to; "clip off")
    out.op = ScriptOp::clip;
    if (!(w.size() == 2 && w[1] == "off")) {
      need(7, "clip PX PY PZ NX NY NZ | clip off");
      for (size_t i = 1; i < 7; ++i)
        out.numbers.push_back(number(w[i], -kScriptMaxWorld, kScriptMaxWorld));
      if (!clip_normal_usable(glm::vec3(out.numbers[3], out.numbers[4], out.numbers[5])))
        throw Error("'clip': the normal (NX NY NZ) must not be zero (a length above 1e-6)");
    }
  } else if (c == "place") {
    need(3, "place X Y");
    out.op = ScriptOp::place;
    out.numbers = {number(w[1], 0.0, kScriptMaxCoordinate),
                   number(w[2], 0.0, kScriptMaxCoordinate)};
  } else if (c == "move") {
    need(4, "move LABEL_ID X Y");
    out.op = ScriptOp::move;
    out.numbers = {number(w[1], 0.0, kScriptMaxLabelId, true),
                   number(w[2], 0.0, kScriptMaxCoordinate),
                   number(w[3], 0.0, kScriptMaxCoordinate)};
  } else if (c == "text") {
    need(3, "text LABEL_ID \"TEXT\"");
    out.op = ScriptOp::text;
    out.numbers = {number(w[1], 0.0, kScriptMaxLabelId, true)};
    out.value = w[2];
    if (out.value.empty()) throw Error("'text' needs a text that is not empty");
  } else if (c == "delete") {
    need(2, "delete LABEL_ID");
    out.op = ScriptOp::delete_label;
    out.numbers = {number(w[1], 0.0, kScriptMaxLabelId, true)};
  } else if (c == "undo" || c == "redo") {
    need(1, c == "undo" ? "undo" : "redo");
    out.op = c == "undo" ? ScriptOp::undo : ScriptOp::redo;
  } else if (c == "save") {
    if (w.size() != 2 && !(w.size() == 3 && (w[2] == "lps" || w[2] == "ras")))
      throw Error("'save' takes the form: save FILE.mrk.json|FILE.fcsv [lps|ras]");
    out.op = ScriptOp::save_labels;
    out.word = w[1];
    out.value = w.size() == 3 ? w[2] : "lps";
  } else if (c == "quit") {
    need(1, "quit");
    out.op = ScriptOp::quit;
  } else {
    throw Error("no command '" + c +
                "' (drag, scroll, key, view, preset, set, hide, show, screenshot, capture, layout, "
                "record, frames, sleep, settle-limit, save-position, report, place, move, text, "
                "delete, undo, redo, save, quit)");
  }
  return out;
}

// A line's words: split at spaces and tabs, up to a '#' (a comment); "a quoted text" is one word
// (spaces and '#' kept; \" is a quote, \\ a backslash).
std::vector<std::string> script_words(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false, quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '\\' && i + 1 < line.size() && (line[i + 1] == '"' || line[i + 1] == '\\')) {
        word += line[++i];
      } else if (c == '"') {
        quoted = false;
      } else {
        word += c;
      }
    } else if (c == '#') {
      break;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      if (in_word) words.push_back(std::move(word));
      word.clear();
      in_word = false;
    } else {
      in_word = true;
      if (c == '"') {
        quoted = true;
      } else {
        word += c;
      }
    }
  }
  if (quoted) throw Error("a quoted text has no closing '\"'");
  if (in_word) words.push_back(std::move(word));
  return words;
}

}  // namespace

std::vector<ScriptCommand> parse_viewer_script(const std::string& text, const std::string& file) {
  std::istringstream in(text);
  std::vector<ScriptCommand> commands;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    try {
      const std::vector<std::string> w = script_words(line);
      if (w.empty()) continue;
      commands.push_back(command(w));
    } catch (const Error& e) {
      throw Error(file + ":" + std::to_string(n) + ": " + e.what());
    }
    commands.back().line = n;
  }
  return commands;
}

}  // namespace strata::app
