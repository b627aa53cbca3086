// The viewer's input scripts (`strata view --script FILE`, docs/viewer.md): text to a list of
// commands with their arguments checked, before the window opens. No Vulkan and no window, so the
// parser is fuzzed (fuzz/fuzz_viewer_script.cpp) and unit-tested alone; app/view_command.cpp
// runs the commands.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace strata::app {

// Limits that keep a script's run bounded: a number outside them is an error, never a hang.
inline constexpr double kScriptMaxCoordinate = 16384.0;  // drag: window pixels, either sign
inline constexpr double kScriptMaxWorld = 1e6;           // crop, clip: world millimetres, either sign
inline constexpr double kScriptMaxScroll = 100.0;        // scroll: wheel ticks, either sign
inline constexpr double kScriptMaxFrames = 100000.0;     // frames N
inline constexpr double kScriptMaxSleep = 600.0;         // sleep SECONDS
inline constexpr double kScriptMaxSettle = 86400.0;      // settle-limit SECONDS
inline constexpr double kScriptMaxVolume = 1023.0;       // preset NAME VOLUME (the scene has fewer)
inline constexpr double kScriptMaxLabelId = 2147483647.0;

enum class ScriptOp {
  drag,
  scroll,
  key,
  view,
  preset,
  set,
  hide,
  show,
  screenshot,
  capture,
  layout,
  record_start,
  record_stop,
  frames,
  sleep,
  save_position,
  settle_limit,
  report,
  place,
  move,
  text,
  delete_label,
  undo,
  redo,
  save_labels,
  crop,
  clip,
  quit
};

// One command: what it does, its words and its numbers, each already checked against its range
// (a key, a button, a view and a preset are known names; `set`'s value is checked against the
// parameter's range by the viewer, app/viewer.h).
struct ScriptCommand {
  size_t line = 0;  // in the file, from 1
  ScriptOp op = ScriptOp::quit;
  std::string word;   // drag: the button; key, view, preset: the name; set: the parameter; files
  std::string value;  // set: the value as written; text: the text; save: lps or ras
  std::vector<double> numbers;  // drag: x0 y0 x1 y1; scroll, hide, show, frames, sleep, preset
  bool shift = false;           // drag ... shift
};

// The commands of a script's text, one a line ('#' starts a comment, blank lines are skipped).
// An Error "FILE:LINE: reason" for the first line that is not a command with valid arguments.
std::vector<ScriptCommand> parse_viewer_script(const std::string& text, const std::string& file);

}  // namespace strata::app
