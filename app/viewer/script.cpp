#include "app/viewer/script.h"

#include <cmath>
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
double number(const std::string& word, double lo, double hi, bool whole) {
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

// Whether `word` is one of the '|'-separated words of `words`.
bool one_of(const std::string& word, const std::string& words) {
  std::istringstream in(words);
  std::string w;
  while (std::getline(in, w, '|'))
    if (w == word) return true;
  return false;
}

void check_key(const std::string& name) {
  if (one_of(name, "left|right|up|down|escape|f12|F12|space")) return;
  if (name.size() == 1 &&
      ((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= '0' && name[0] <= '9')))
    return;
  throw Error("no key '" + name + "' (a-z, 0-9, left, right, up, down, escape, f12, space)");
}

void check_preset(const std::string& name) {
  std::string names;
  for (const TransferFunctionPreset& p : transfer_function_presets()) {
    if (name == p.name) return;
    names += std::string(names.empty() ? "" : ", ") + p.name;
  }
  throw Error("no transfer-function preset '" + name + "' (" + names + ")");
}

// Checks a word against its argument and puts it into the command.
void read_arg(const std::string& command, const ScriptArg& a, const std::string& w,
              ScriptCommand& out, int& words) {
  switch (a.kind) {
    case ArgKind::literal:
      out.flag = true;
      return;
    case ArgKind::number:
    case ArgKind::whole:
      out.numbers.push_back(number(w, a.lo, a.hi, a.kind == ArgKind::whole));
      return;
    case ArgKind::button:
      if (!one_of(w, a.name)) throw Error("no mouse button '" + w + "' (left, right, middle)");
      break;
    case ArgKind::key:
      check_key(w);
      break;
    case ArgKind::view:
      if (!anatomical_view_named(w))
        throw Error("no view '" + w + "' (anterior, posterior, left, right, superior, inferior)");
      break;
    case ArgKind::preset:
      check_preset(w);
      break;
    case ArgKind::text:
      if (w.empty()) throw Error("'" + command + "' needs a text that is not empty");
      out.value = w;
      return;
    case ArgKind::choice:
    case ArgKind::word:
      break;
  }
  (words++ == 0 ? out.word : out.value) = w;
}

// Whether the line's words have the command's shape: their count, and its literal words (and
// choices) where they stand.
bool fits(const ScriptCommandSpec& spec, const std::vector<std::string>& w) {
  const size_t given = w.size() - 1;
  if (given > spec.args.size() || given + spec.optional < spec.args.size()) return false;
  for (size_t i = 0; i < given; ++i) {
    const ScriptArg& a = spec.args[i];
    if ((a.kind == ArgKind::literal || a.kind == ArgKind::choice) && !one_of(w[i + 1], a.name))
      return false;
  }
  return true;
}

ScriptCommand command(const std::vector<std::string>& w) {
  const std::vector<ScriptCommandSpec>& table = viewer_script_commands();
  std::string forms, names;
  for (size_t k = 0; k < table.size(); ++k) {
    const ScriptCommandSpec& spec = table[k];
    if (names.find(std::string(spec.name) + ",") == std::string::npos)
      names += std::string(spec.name) + ", ";
    if (w[0] != spec.name) continue;
    forms += (forms.empty() ? "" : " | ") + script_form(spec);
    if (!fits(spec, w)) continue;
    ScriptCommand out;
    out.command = k;
    out.name = spec.name;
    int words = 0;
    for (size_t i = 0; i < spec.args.size(); ++i) {
      const ScriptArg& a = spec.args[i];
      if (i + 1 < w.size()) {
        read_arg(spec.name, a, w[i + 1], out, words);
      } else if (a.kind == ArgKind::number || a.kind == ArgKind::whole) {
        out.numbers.push_back(a.lo);  // (an optional number left out: its lowest value)
      } else if (a.kind != ArgKind::literal) {
        read_arg(spec.name, a, a.fallback, out, words);
      }
    }
    if (spec.check) spec.check(out);
    return out;
  }
  if (!forms.empty()) throw Error("'" + w[0] + "' takes the form: " + forms);
  throw Error("no command '" + w[0] + "' (" + names.substr(0, names.size() - 2) + ")");
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

const std::vector<ScriptCommandSpec>& viewer_script_commands() {
  using namespace script_args;
#define VIEWER_APPLY(...) nullptr
  static const std::vector<ScriptCommandSpec> table = {
#include "app/viewer/script_commands.inc"
  };
#undef VIEWER_APPLY
  return table;
}

ScriptCommand viewer_command(const std::vector<std::string>& words) {
  if (words.empty()) throw Error("no command");
  return command(words);
}

const ScriptCommandSpec& ScriptCommand::spec() const {
  return viewer_script_commands().at(command);
}

std::string script_form(const ScriptCommandSpec& spec) {
  std::string form = spec.name;
  for (size_t i = 0; i < spec.args.size(); ++i) {
    const bool first_optional = i + spec.optional == spec.args.size();
    form += std::string(first_optional ? " [" : " ") + spec.args[i].name;
  }
  return form + (spec.optional > 0 ? "]" : "");
}

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
