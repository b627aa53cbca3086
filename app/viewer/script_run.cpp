#include "app/viewer/script_run.h"

#include <cstdio>
#include <map>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

#include "app/output_files.h"
#include "app/viewer/parameters.h"
#include "app/viewer/viewer.h"
#include "engine/core/error.h"
#include "engine/core/text_file.h"
#include "engine/scene/fitted_camera.h"
#include "engine/scene/value_limits.h"

namespace strata::app {
namespace {

const std::map<std::string, int>& named_keys() {
  static const std::map<std::string, int> named = {
      {"left", GLFW_KEY_LEFT}, {"right", GLFW_KEY_RIGHT},   {"up", GLFW_KEY_UP},
      {"down", GLFW_KEY_DOWN}, {"escape", GLFW_KEY_ESCAPE}, {"f12", GLFW_KEY_F12},
      {"F12", GLFW_KEY_F12},   {"space", GLFW_KEY_SPACE},
  };
  return named;
}

int mouse_code(const std::string& name) {
  if (name == "left") return GLFW_MOUSE_BUTTON_LEFT;
  if (name == "right") return GLFW_MOUSE_BUTTON_RIGHT;
  return GLFW_MOUSE_BUTTON_MIDDLE;
}

// drag: press, move in 8 steps, release.
void drag(Viewer& viewer, const ScriptCommand& c) {
  const std::vector<double>& n = c.numbers;
  const int button = mouse_code(c.word);
  const glm::vec2 from{float(n[0]), float(n[1])};
  const glm::vec2 to{float(n[2]), float(n[3])};
  const int mods = c.flag ? GLFW_MOD_SHIFT : 0;
  viewer.cursor(from);
  viewer.mouse_button(button, GLFW_PRESS, mods);
  for (int i = 1; i <= 8; ++i) viewer.cursor(from + (to - from) * (float(i) / 8.0f));
  viewer.mouse_button(button, GLFW_RELEASE, mods);
}

glm::vec3 vec3_at(const std::vector<double>& n, size_t i) {
  return {float(n[i]), float(n[i + 1]), float(n[i + 2])};
}

nlohmann::json report_json(const Viewer& viewer) {
  nlohmann::json view = nlohmann::json::array();
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) view.push_back(viewer.camera().view[col][row]);
  }
  nlohmann::json report = {{"frames", viewer.summary().frames},
                           {"settled", viewer.settled()},
                           {"busy", viewer.busy()},
                           {"trials", viewer.summary().trials},
                           {"panel", viewer.panel_rect()},
                           {"view", view},
                           {"crop", nullptr},
                           {"clip", nlohmann::json::array()}};
  if (const auto& box = viewer.cuts().crop)
    report["crop"] = {(*box)[0].x, (*box)[0].y, (*box)[0].z, (*box)[1].x, (*box)[1].y, (*box)[1].z};
  for (const glm::vec4& plane : viewer.cuts().planes)
    report["clip"].push_back({plane.x, plane.y, plane.z, plane.w});
  return report;
}

using Apply = void (*)(ScriptRun&, const ScriptCommand&);

// The table's applications, in its order (app/viewer/script_commands.inc).
const std::vector<Apply>& applications() {
  using namespace script_args;
#define VIEWER_APPLY(...) [](ScriptRun & run, [[maybe_unused]] const ScriptCommand& c) __VA_ARGS__
  static const std::vector<ScriptCommandSpec> table = {
#include "app/viewer/script_commands.inc"
  };
#undef VIEWER_APPLY
  static const std::vector<Apply> apply = [] {
    std::vector<Apply> out;
    for (const ScriptCommandSpec& spec : table) out.push_back(spec.apply);
    return out;
  }();
  return apply;
}

}  // namespace

int key_code(const std::string& name) {  // (parse_viewer_script checked the name)
  if (const auto it = named_keys().find(name); it != named_keys().end()) return it->second;
  if (name[0] >= 'a' && name[0] <= 'z') return GLFW_KEY_A + (name[0] - 'a');
  return GLFW_KEY_0 + (name[0] - '0');
}

std::optional<std::string> key_name(int key) {
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return std::string(1, char('a' + (key - GLFW_KEY_A)));
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return std::string(1, char('0' + (key - GLFW_KEY_0)));
  for (const auto& [name, code] : named_keys())
    if (code == key) return name;
  return std::nullopt;
}

void apply_script_command(ScriptRun& run, const ScriptCommand& command) {
  applications().at(command.command)(run, command);
}

std::vector<ScriptCommand> read_script(const std::string& path) {
  std::vector<ScriptCommand> commands = parse_viewer_script(read_text_file(path), path);
  for (const ScriptCommand& c : commands) {
    if (c.name != "set") continue;
    try {
      check_viewer_parameter(c.word, c.value);
    } catch (const Error& e) {
      throw Error(path + ":" + std::to_string(c.line) + ": " + e.what());
    }
  }
  return commands;
}

Script::Script(std::string path, std::vector<ScriptCommand> lines, double settle_limit)
    : path_(std::move(path)), lines_(std::move(lines)) {
  run_.settle_limit = settle_limit;
}

void Script::check_outputs(const std::string& labels) const {
  check_script_outputs(path_, lines_, labels);
}

void Script::wait_for(const Viewer& viewer) {
  const auto now = std::chrono::steady_clock::now();
  if (!waiting_since_) waiting_since_ = now;
  if (std::chrono::duration<double>(now - *waiting_since_).count() < run_.settle_limit) return;
  const std::string where =
      done() ? path_ + ": after the last line" : path_ + ":" + std::to_string(lines_[next_].line);
  throw Error(where + ": the view did not settle within " + value_limits::shown(run_.settle_limit) +
              " s (--settle-limit, settle-limit); still busy: " + viewer.unsettled());
}

void Script::run_next(Viewer& viewer) {
  waiting_since_.reset();
  const ScriptCommand& line = lines_[next_++];
  run_.viewer = &viewer;
  try {
    apply_script_command(run_, line);
  } catch (const Error& e) {
    throw Error(path_ + ":" + std::to_string(line.line) + ": " + e.what());
  }
}

}  // namespace strata::app
