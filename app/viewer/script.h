// The viewer's commands, as input scripts write them (`strata view --script FILE`,
// docs/viewer.md). Each command is declared once, in app/viewer/script_commands.inc: its words
// with their ranges, its help and how it applies. This side reads a script's text into commands
// with their arguments checked, before the window opens; it has no Vulkan and no window, so it is
// fuzzed (fuzz/fuzz_viewer_script.cpp) and unit-tested alone. app/viewer/script_run.cpp applies
// the commands to a viewer.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace strata::app {

// Limits that keep a script's run bounded: a number outside them is an error, never a hang.
inline constexpr double kScriptMaxCoordinate = 16384.0;  // drag: window pixels, either sign
inline constexpr double kScriptMaxWorld = 1e6;        // crop, clip: world millimetres, either sign
inline constexpr double kScriptMaxScroll = 100.0;     // scroll: wheel ticks, either sign
inline constexpr double kScriptMaxFrames = 100000.0;  // frames N
inline constexpr double kScriptMaxSleep = 600.0;      // sleep SECONDS
inline constexpr double kScriptMaxSettle = 86400.0;   // settle-limit SECONDS
inline constexpr double kScriptMaxVolume = 1023.0;    // preset NAME VOLUME (the scene has fewer)
inline constexpr double kScriptMaxLabelId = 2147483647.0;

// What one word of a command is. Numbers go to ScriptCommand::numbers in order, the first other
// word to `word`, the second to `value`; a literal only has to be there (an optional one sets
// `flag`).
enum class ArgKind {
  literal,  // the name itself
  number,   // a finite number in [lo, hi]
  whole,    // a whole number in [lo, hi]
  button,   // left, right, middle
  key,      // a-z, 0-9, left, right, up, down, escape, f12, space
  view,     // an anatomical view
  preset,   // a transfer-function preset's name
  choice,   // one of the name's words ("lps|ras")
  word,     // any word (a file, a parameter, a name)
  text      // any word but an empty one
};

struct ScriptArg {
  ArgKind kind = ArgKind::word;
  const char* name = "";  // as the form shows it; a literal's or a choice's words
  double lo = 0.0, hi = 0.0;
  const char* fallback = "";  // an optional word left out
};

struct ScriptCommand;
struct ScriptRun;  // the state a script runs with (app/viewer/script_run.h)

// A command: several may share a name (record start | record stop); the first whose words fit
// the line reads it.
struct ScriptCommandSpec {
  const char* name;
  std::vector<ScriptArg> args;
  size_t optional = 0;  // the last `optional` arguments may be left out
  const char* help = "";
  // A command writing the file in `word`: what to call it when that file is refused
  // (app/output_files.h); null: it writes none.
  const char* writes = nullptr;
  void (*check)(const ScriptCommand&) = nullptr;  // checks across the arguments (an Error)
  void (*apply)(ScriptRun&, const ScriptCommand&) = nullptr;  // (null on the parsing side)
};

// One command of a script, its arguments checked against their ranges (`set`'s value is checked
// against the parameter's by the viewer, app/viewer/parameters.h).
struct ScriptCommand {
  size_t line = 0;     // in the file, from 1
  size_t command = 0;  // its index in viewer_script_commands()
  std::string name;    // the command's first word
  std::string word;    // drag: the button; key, view, preset: the name; set: the parameter; files
  std::string value;   // set: the value as written; text: the text; save: lps or ras
  std::vector<double> numbers;  // drag: x0 y0 x1 y1; scroll, hide, show, frames, sleep, preset
  bool flag = false;            // an optional literal that is there (drag ... shift)
  const ScriptCommandSpec& spec() const;
};

// Every command, in the table's order.
const std::vector<ScriptCommandSpec>& viewer_script_commands();
// A command's form as its errors and the docs write it ("drag left|right|middle X0 Y0 ...").
std::string script_form(const ScriptCommandSpec& spec);

// One command from its words (the name first), checked as a script line is: what the panel and
// the keys hand the viewer (Viewer::submit). An Error where they are not a command.
ScriptCommand viewer_command(const std::vector<std::string>& words);

// The commands of a script's text, one a line ('#' starts a comment, blank lines are skipped).
// An Error "FILE:LINE: reason" for the first line that is not a command with valid arguments.
std::vector<ScriptCommand> parse_viewer_script(const std::string& text, const std::string& file);

// The table's helpers (app/viewer/script_commands.inc).
namespace script_args {
inline ScriptArg literal(const char* word) {
  return {ArgKind::literal, word};
}
inline ScriptArg number(const char* name, double lo, double hi) {
  return {ArgKind::number, name, lo, hi};
}
inline ScriptArg whole(const char* name, double lo, double hi) {
  return {ArgKind::whole, name, lo, hi};
}
inline ScriptArg of(ArgKind kind, const char* name) {
  return {kind, name};
}
inline ScriptArg choice(const char* words, const char* fallback) {
  return {ArgKind::choice, words, 0.0, 0.0, fallback};
}
inline ScriptArg label_id() {
  return whole("ID", 0.0, kScriptMaxLabelId);
}
inline ScriptArg pixel(const char* name) {
  return number(name, 0.0, kScriptMaxCoordinate);
}
inline ScriptArg world(const char* name) {
  return number(name, -kScriptMaxWorld, kScriptMaxWorld);
}
}  // namespace script_args

}  // namespace strata::app
