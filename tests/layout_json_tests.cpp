// `strata render --layout`'s file: valid JSON whatever the label texts hold, numbers as placed.
#include <doctest/doctest.h>

#include <limits>

#include <nlohmann/json.hpp>

#include "frame/labelled_render.h"
#include "labeling/layout_metrics.h"

namespace strata {
namespace {

// 1000 bytes of text with everything JSON must escape and a two-byte UTF-8 character.
std::string awkward_text() {
  const std::string piece = "Nucleus \"caudatus\" \\ left \xC3\xA9";  // é
  std::string text;
  while (text.size() + piece.size() <= 1000) text += piece;
  text.append(1000 - text.size(), 'x');
  return text;
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("layout_json_round_trips_long_and_unicode_texts") {
    LabelledFrame frame;
    frame.size = {640, 480};
    LabelLayout label;
    label.id = 17;
    label.text = awkward_text();
    label.layer = 2;
    label.anchor = {123.25f, 0.1f};
    label.box_origin = {300.5f, 41.75f};
    label.box_size = {96.0f, 18.0f};
    label.shown = true;
    label.cost = 3.14159f;
    frame.labels = {label, LabelLayout{}};
    REQUIRE(label.text.size() == 1000);

    const nlohmann::json layout = nlohmann::json::parse(layout_json(frame));
    CHECK(layout["width"] == 640);
    CHECK(layout["height"] == 480);
    REQUIRE(layout["labels"].size() == 2);
    const nlohmann::json& l = layout["labels"][0];
    CHECK(l["id"] == 17);
    CHECK(l["text"].get<std::string>() == label.text);
    CHECK(l["layer"] == 2);
    // Floats are written with the digits that read back as the very same float.
    const auto as_float = [](const nlohmann::json& value) { return value.get<float>(); };
    CHECK(as_float(l["anchor"][0]) == label.anchor.x);
    CHECK(as_float(l["anchor"][1]) == label.anchor.y);
    CHECK(as_float(l["box"][0]) == label.box_origin.x);
    CHECK(as_float(l["box"][1]) == label.box_origin.y);
    CHECK(as_float(l["box"][2]) == label.box_size.x);
    CHECK(as_float(l["box"][3]) == label.box_size.y);
    CHECK(l["shown"] == true);
    CHECK(as_float(l["cost"]) == label.cost);
    CHECK(layout["labels"][1]["text"] == "");
    CHECK(layout["labels"][1]["shown"] == false);
  }

  TEST_CASE("layout_json_writes_opacity_target_and_seconds_that_eval_reads_back") {
    LabelledFrame frame;
    frame.size = {64, 48};
    frame.seconds = 1.0 / 12.0;
    LabelLayout heading;
    heading.id = 1;
    heading.box_origin = {10.5f, 4.0f};
    heading.box_size = {20.0f, 8.0f};
    heading.placed = heading.shown = true;
    heading.opacity = 0.625f;
    heading.target_origin = glm::vec2(30.25f, 6.0f);
    LabelLayout hidden;
    hidden.id = 2;
    frame.labels = {heading, hidden};
    const std::string text = layout_json(frame);
    const nlohmann::json layout = nlohmann::json::parse(text);
    CHECK(layout["seconds"].get<double>() == 1.0 / 12.0);
    CHECK(layout["labels"][0]["opacity"] == 0.625);
    CHECK(layout["labels"][0]["target"] == nlohmann::json({30.25, 6.0, 20.0, 8.0}));
    CHECK(layout["labels"][1]["opacity"] == 0.0);
    CHECK(layout["labels"][1]["target"].is_null());
    const Layout read = parse_layout(layout, "frame.json");
    REQUIRE(read.seconds);
    CHECK(*read.seconds == 1.0 / 12.0);
    CHECK(read.labels[0].opacity == 0.625);
    REQUIRE(read.labels[0].target);
    CHECK(read.labels[0].target->min == glm::dvec2(30.25, 6.0));
    CHECK_FALSE(read.labels[1].target);
    // A still has no time step.
    frame.seconds.reset();
    CHECK(nlohmann::json::parse(layout_json(frame))["seconds"].is_null());
  }

  TEST_CASE("front_alpha_is_written_read_back_and_summed_over_shown_rear_labels") {
    // Two shown rear labels (front alpha 0.2 and 0.9), one on the front layer and one not
    // measured: eval counts the two, one of them seen (<= 0.3).
    LabelledFrame frame;
    frame.size = {64, 48};
    for (int i = 0; i < 4; ++i) {
      LabelLayout l;
      l.id = i + 1;
      l.layer = i == 2 ? 0u : 1u;
      l.box_origin = {float(i * 15), 4.0f};
      l.box_size = {10.0f, 8.0f};
      l.placed = l.shown = true;
      l.opacity = 1.0f;
      l.front_alpha = i == 0 ? 0.2f : i == 1 ? 0.9f : i == 2 ? 0.0f : std::nanf("");
      frame.labels.push_back(l);
    }
    const nlohmann::json layout = nlohmann::json::parse(layout_json(frame));
    CHECK(layout["labels"][0]["front_alpha"].get<double>() == doctest::Approx(0.2));
    CHECK(layout["labels"][3]["front_alpha"].is_null());
    const FrameMetrics m = frame_metrics(parse_layout(layout, "frame.json"));
    CHECK(m.rear_anchors == 2);
    CHECK(m.rear_anchors_seen == 1);
    CHECK(m.rear_front_alpha_mean == doctest::Approx(0.55));
    CHECK(m.rear_front_alpha_max == doctest::Approx(0.9));
    nlohmann::json bad = layout;
    bad["labels"][0]["front_alpha"] = 1.5;
    CHECK_THROWS_WITH(parse_layout(bad, "frame.json"),
                      doctest::Contains("labels[0].front_alpha: expected a number from 0 to 1"));
  }

  TEST_CASE("anchor_hidden_is_written_read_back_and_counted_over_shown_labels") {
    // Hidden anchors (two shown, one not shown), a seen one and one not measured: the file says
    // which (null where not measured), reads back the same, and eval counts the shown hidden ones.
    LabelledFrame frame;
    frame.size = {80, 48};
    const std::optional<bool> hidden[5] = {true, true, true, false, std::nullopt};
    for (int i = 0; i < 5; ++i) {
      LabelLayout l;
      l.id = i + 1;
      l.box_origin = {float(i * 15), 4.0f};
      l.box_size = {10.0f, 8.0f};
      l.placed = l.shown = i != 2;
      l.opacity = l.placed ? 1.0f : 0.0f;
      l.anchor_hidden = hidden[i];
      frame.labels.push_back(l);
    }
    const nlohmann::json layout = nlohmann::json::parse(layout_json(frame));
    CHECK(layout["labels"][0]["anchor_hidden"] == true);
    CHECK(layout["labels"][3]["anchor_hidden"] == false);
    CHECK(layout["labels"][4]["anchor_hidden"].is_null());
    const Layout read = parse_layout(layout, "frame.json");
    for (size_t i = 0; i < 5; ++i) CHECK(read.labels[i].anchor_hidden == hidden[i]);
    const FrameMetrics m = frame_metrics(read);
    CHECK(m.anchors_hidden == 2);
    CHECK(to_json(m)["anchors_hidden"] == 2);
    CHECK(sum_frame_metrics({m, m}).anchors_hidden == 4);
    nlohmann::json bad = layout;
    bad["labels"][0]["anchor_hidden"] = 1;
    CHECK_THROWS_WITH(parse_layout(bad, "frame.json"),
                      doctest::Contains("labels[0].anchor_hidden: expected true or false"));
  }

  TEST_CASE("layout_json_writes_non_finite_numbers_as_null") {
    // JSON has no inf or NaN: a label that was never placed must not make the file unreadable.
    LabelledFrame frame;
    frame.size = {64, 64};
    LabelLayout label;
    label.cost = std::numeric_limits<float>::infinity();
    label.box_origin = {std::numeric_limits<float>::quiet_NaN(), 1.0f};
    frame.labels = {label};
    const std::string text = layout_json(frame);
    CHECK(text.find("inf") == std::string::npos);
    CHECK(text.find("nan") == std::string::npos);
    const nlohmann::json layout = nlohmann::json::parse(text);
    CHECK(layout["labels"][0]["cost"].is_null());
    CHECK(layout["labels"][0]["box"][0].is_null());
    CHECK(layout["labels"][0]["box"][1] == 1.0);
  }
}

}  // namespace strata
