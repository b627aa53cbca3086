// Input scripts run on a viewer (`strata view --script FILE`, docs/viewer.md): each command once
// the viewer has settled (nothing moves, no frame due), so a script does the same whatever the
// device's speed. The commands apply as app/viewer/script_commands.inc declares.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/script.h"

namespace strata::app {

class Viewer;

// What a command may change besides the viewer: the frames it asked for, a sleep, the limit.
struct ScriptRun {
  Viewer* viewer = nullptr;
  uint32_t frames = 0;  // frames still due
  std::chrono::steady_clock::time_point wake{};
  double settle_limit = 0.0;  // seconds (--settle-limit, the script's settle-limit)
};

// The script's commands, checked before the window opens: the parser's checks, and each `set`
// against its parameter's range.
std::vector<ScriptCommand> read_script(const std::string& path);

class Script {
 public:
  Script(std::string path, std::vector<ScriptCommand> lines, double settle_limit);

  bool done() const { return next_ >= lines_.size(); }
  // The files the script writes, as outputs (app/output_files.h), once the scene is read.
  void check_outputs(const std::string& labels) const;
  // Frames the last command asked for that are still due.
  uint32_t frames_due() const { return run_.frames; }
  void frame_drawn() {
    if (run_.frames > 0) --run_.frames;
  }
  // Whether a `sleep` is still running (the viewer processes events meanwhile).
  bool sleeping() const { return std::chrono::steady_clock::now() < run_.wake; }

  void run_next(Viewer& viewer);
  // The script waits for a busy viewer (no frames due, no sleep): an Error naming the line and
  // what had not settled once that wait has lasted the settle limit.
  void wait_for(const Viewer& viewer);

 private:
  std::string path_;
  std::vector<ScriptCommand> lines_;
  size_t next_ = 0;
  ScriptRun run_;
  std::optional<std::chrono::steady_clock::time_point> waiting_since_;
};

// A key's GLFW code from its name in the `key` command, and back (none: a key no command names).
int key_code(const std::string& name);
std::optional<std::string> key_name(int key);

// Applies one command to `run`'s viewer now (an Error where it cannot).
void apply_script_command(ScriptRun& run, const ScriptCommand& command);

}  // namespace strata::app
