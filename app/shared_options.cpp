// Options several commands declare alike (device, label look, tidy-up, constraints, placement
// queue), and the checks that run over a whole command's options.
#include <algorithm>
#include <cstdlib>
#include <string>

#include "app/commands.h"
#include "frame/labelled_render.h"

namespace strata::app {

ContextOptions DeviceOptions::context() const {
  ContextOptions options;
  options.device_selector = device;
  const char* env = std::getenv("STRATA_VALIDATE");
#ifdef NDEBUG
  options.validation = validate || (env && std::string(env) == "1");
#else
  options.validation = !(env && std::string(env) == "0");
#endif
  return options;
}

void refuse_empty_values(CLI::App& app) {
  const CLI::Validator not_empty(
      [](std::string& input) { return input.empty() ? std::string("an empty value") : ""; }, "");
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_size() != 0) option->check(not_empty);
  }
  for (CLI::App* sub : app.get_subcommands({})) refuse_empty_values(*sub);
}

void check_options_apply(const CLI::App* cmd, bool has_scene,
                         std::initializer_list<const char*> pattern_options,
                         std::initializer_list<const char*> pattern_only) {
  const auto named = [](std::initializer_list<const char*> names, const CLI::Option* option) {
    return std::any_of(names.begin(), names.end(),
                       [&](const char* name) { return option->check_name(name); });
  };
  for (const CLI::Option* option : cmd->get_options()) {
    if (option->count() == 0 || !option->nonpositional()) continue;
    if (has_scene && named(pattern_only, option))
      throw UsageError(option->get_name() + ": applies to the test pattern only (no scene)");
    if (!has_scene && !named(pattern_options, option) && !named(pattern_only, option))
      throw UsageError(option->get_name() +
                       ": needs a scene (with none given the test pattern is drawn)");
  }
}

void add_placement_option(CLI::App* cmd, std::string& mode) {
  cmd->add_option("--placement", mode,
                  "beside: the placement runs beside the frames, which never wait for it; frame: "
                  "in every frame; auto: beside where the device has a second queue")
      ->check(CLI::IsMember({"auto", "beside", "frame"}))
      ->capture_default_str();
}

bool placement_beside(const std::string& mode, const Context& ctx) {
  return mode == "beside" || (mode == "auto" && ctx.separate_placement_queue());
}

Ghosting look_ghosting(const LabelLookOptions& o, const Scene& scene) {
  const float radius = o.ghost_radius.value_or(scene.settings.ghost_radius);
  // (a connector's lens a third of the anchor's wide)
  return {o.ghost.value_or(scene.settings.ghost), radius, o.ghost_leaders ? radius / 3.0f : 0.0f};
}

void add_tidy_rounds_option(CLI::App* cmd, uint32_t& rounds, const char* when) {
  cmd->add_option("--tidy-rounds", rounds, std::string("rounds of the tidy-up ") + when)
      ->check(whole_range(0, TIDY_ROUNDS_MAX))
      ->capture_default_str();
}

void add_hard_option(CLI::App* cmd, bool& hard) {
  cmd->add_flag("--hard", hard, "hard constraints: a label with no allowed position is hidden");
}

void add_greedy_option(CLI::App* cmd, PlacementMethod& method) {
  cmd->add_option_function<std::string>(
         "--greedy",
         [&method](const std::string& name) {
           method = name == "rounds" ? PlacementMethod::rounds : PlacementMethod::sequential;
         },
         "how the greedy placement decides the labels: sequential (one by one in insertion "
         "order, the thesis's loop) or rounds (in parallel rounds: faster on a GPU, fewer labels "
         "shown in crowded pictures)")
      ->check(CLI::IsMember({"sequential", "rounds"}))
      ->default_str("sequential");
}

void add_background_option(CLI::App* cmd, Background& background) {
  cmd->add_option_function<std::string>(
         "--background",
         [&background](const std::string& text) { background = parse_background(text); },
         "what the picture shows where the scene and labels leave it empty: black, white, #rrggbb "
         "or transparent (PNG only, with alpha); the labels are placed alike on any")
      ->default_str("black");
}

void add_label_look_options(CLI::App* cmd, LabelLookOptions& o) {
  cmd->add_option("--label-scale", o.label_scale, "label text and boxes times this (0.25 to 4)")
      ->check(finite_range(0.25, 4.0))
      ->capture_default_str();
  cmd->add_flag("--layer-colors", o.layer_colors,
                "label borders in their depth layer's colour (front to back: orange, blue, green, "
                "pink, ...)");
  cmd->add_option("--ghost", o.ghost,
                  "ghosting: the layers in front of a rear label's anchor made this much more "
                  "transparent around it (0: off, 1: fully open at the anchor; default: the "
                  "scene's settings.ghost, else 1)")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--ghost-radius", o.ghost_radius,
                  "the ghosting lens's radius, a share of the picture's shorter side (default: the "
                  "scene's settings.ghost_radius, else 0.1)")
      ->check(finite_range(kGhostRadiusMin, kGhostRadiusMax));
  cmd->add_flag("--ghost-leaders", o.ghost_leaders,
                "ghosting opens the layers along each rear label's connector too");
}

}  // namespace strata::app
