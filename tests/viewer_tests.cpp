// The interactive viewer end to end, under Xvfb on lavapipe with validation on: input scripts
// drive it with the events a user makes and the screenshots and layouts show each effect; one
// test sends real X events with xdotool.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "engine/core/png.h"
#include "engine/scene/camera.h"
#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/label_file_writer.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/scene_bounds.h"
#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {
namespace {

using test::run_strata;

const std::string kScene = STRATA_SOURCE_DIR "/assets/scenes/head.json";
constexpr int kWidth = 160, kHeight = 120;

struct LabelBox {
  int id = 0;
  bool shown = false;
  glm::vec2 anchor{0.0f};
  glm::vec4 box{0.0f};  // x, y, width, height
};

std::vector<LabelBox> read_layout(const std::filesystem::path& path) {
  const auto json = nlohmann::json::parse(test::read_file(path));
  std::vector<LabelBox> out;
  for (const auto& l : json.at("labels")) {
    out.push_back({l.at("id").get<int>(),
                   l.at("shown").get<bool>(),
                   {l.at("anchor")[0].get<float>(), l.at("anchor")[1].get<float>()},
                   {l.at("box")[0].get<float>(), l.at("box")[1].get<float>(),
                    l.at("box")[2].get<float>(), l.at("box")[3].get<float>()}});
  }
  return out;
}

bool inside(glm::vec2 p) {
  return p.x >= 0.0f && p.y >= 0.0f && p.x < float(kWidth) && p.y < float(kHeight);
}

// Mean distance of the anchors in the image from their centroid (a zoom scales it).
float spread(const std::vector<LabelBox>& labels) {
  glm::vec2 centre{0.0f};
  int n = 0;
  for (const auto& l : labels) {
    if (!inside(l.anchor)) continue;
    centre += l.anchor;
    ++n;
  }
  centre /= float(std::max(n, 1));
  float sum = 0.0f;
  for (const auto& l : labels) {
    if (inside(l.anchor)) sum += glm::length(l.anchor - centre);
  }
  return sum / float(std::max(n, 1));
}

float mean_leader(const std::vector<LabelBox>& labels) {
  float sum = 0.0f;
  int n = 0;
  for (const auto& l : labels) {
    if (!l.shown) continue;
    const glm::vec2 centre{l.box.x + 0.5f * l.box.z, l.box.y + 0.5f * l.box.w};
    sum += glm::length(centre - l.anchor);
    ++n;
  }
  return sum / float(std::max(n, 1));
}

// Pixels that differ by more than 8 in some channel, inside `region` (x, y, w, h) or anywhere.
size_t changed_pixels(const Rgba8Image& a, const Rgba8Image& b,
                      std::optional<glm::vec4> region = {}) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  size_t n = 0;
  for (uint32_t y = 0; y < a.height; ++y) {
    for (uint32_t x = 0; x < a.width; ++x) {
      if (region && (float(x) < region->x || float(y) < region->y ||
                     float(x) >= region->x + region->z || float(y) >= region->y + region->w)) {
        continue;
      }
      const size_t i = (size_t(y) * a.width + x) * 4;
      for (int c = 0; c < 3; ++c) {
        if (std::abs(int(a.pixels[i + c]) - int(b.pixels[i + c])) > 8) {
          ++n;
          break;
        }
      }
    }
  }
  return n;
}

// The viewer's camera as a `report` file gives its view matrix (the test scene's lens).
Camera reported_camera(const std::filesystem::path& report) {
  const auto json = nlohmann::json::parse(test::read_file(report));
  Camera camera = load_scene(kScene).camera;
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) camera.view[col][row] = json.at("view")[col * 4 + row];
  return camera;
}

// (--no-optimize: after each of its many steps the optimisation on idle's trials, and the labels'
// move to the order it keeps, would more than double the test's time; nothing here depends on
// the order)
const std::string kManySteps = "--no-optimize --no-panel";

// Runs `strata view` on the test scene with `script` (written into `dir`).
test::CommandResult view(const std::filesystem::path& dir, const std::string& script,
                         const std::string& options = "--no-panel") {
  const auto path = test::write_file(dir / "script.txt", script);
  return run_strata("--validate view " + kScene + " --size " + std::to_string(kWidth) + "x" +
                    std::to_string(kHeight) + " " + options + " --screenshot-dir " + dir.string() +
                    " --script " + path.string());
}

}  // namespace

TEST_SUITE("window") {
  // Labels of one's own (issue 36's session): five labels placed on head.json from two views, one
  // dragged by its anchor in place mode, one renamed in non-ASCII text, one moved, one deleted
  // and the deletion undone, saved as .mrk.json
  // in RAS and as .fcsv in LPS. Both files hold the 5 new ones (not the scene's 11) with the
  // same points (within 0.01 mm); each new anchor lies on the ray of the pixel it was placed or
  // moved at (the camera from `report`); `strata render --labels` shows them on the scan.
  // The crop box from a script: the picture shows the head cut below z = 40 (from the front, its
  // top rows empty), the box's edges are drawn over the window's picture, labels anchored in
  // the cut part hide, and `crop off` brings the whole head back.
  TEST_CASE("viewer_crop_box_cuts_the_picture_is_drawn_and_hides_cut_labels") {
    const auto dir = test::fresh_folder("viewer", "crop");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto r =
        view(dir, "view anterior\nlayout " + d("whole.json") + "\nscreenshot " + d("whole.png") +
                      "\ncrop -100 -120 -60 100 120 10\nlayout " + d("cut.json") + "\nscreenshot " +
                      d("cut.png") + "\ncapture " + d("cut-window.png") +
                      "\ncrop off\nscreenshot " + d("again.png") + "\nquit\n");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const Rgba8Image whole = read_png(d("whole.png")), cut = read_png(d("cut.png"));
    CHECK(changed_pixels(whole, cut) > 1000);
    CHECK(changed_pixels(cut, read_png(d("again.png"))) > 1000);  // (the whole head again)
    // (the box's edges: the orange of draw_crop_box, in the window's picture only)
    const auto orange = [](const Rgba8Image& image) {
      size_t n = 0;
      for (size_t p = 0; p + 3 < image.pixels.size(); p += 4)
        n += image.pixels[p] > 200 && image.pixels[p + 1] > 150 && image.pixels[p + 1] < 230 &&
             image.pixels[p + 2] < 120;
      return n;
    };
    CHECK(orange(read_png(d("cut-window.png"))) > 100);
    CHECK(orange(cut) < orange(read_png(d("cut-window.png"))) / 4);
    // Labels anchored above z = 10 are cut away with the head there.
    const Scene scene = load_scene(kScene);
    const auto shown = [&](const char* name) {
      const nlohmann::json layout = nlohmann::json::parse(test::read_file(d(name)));
      std::vector<int> ids;
      for (const auto& l : layout.at("labels"))
        if (l.at("shown").get<bool>()) ids.push_back(l.at("id").get<int>());
      return ids;
    };
    for (const int id : shown("cut.json")) {
      for (const Label& l : scene.labels)
        if (l.id == id) CHECK(l.anchor.z <= 10.0f);
    }
    // (and one shown before, anchored above the cut, is hidden: the check above is not empty)
    const std::vector<int> now = shown("cut.json");
    size_t hidden_above = 0;
    for (const int id : shown("whole.json")) {
      for (const Label& l : scene.labels)
        if (l.id == id && l.anchor.z > 10.0f && std::find(now.begin(), now.end(), id) == now.end())
          ++hidden_above;
    }
    CHECK(hidden_above > 0);
  }

  // The handles of the viewer's cut-aways, dragged as a user does (script drags: a press on the
  // handle's pixel, the pointer moved, the release): the box's bottom face and a clipping plane
  // move by what the pointer's move is in millimetres at the handle, and the picture changes with
  // them.
  TEST_CASE("viewer_crop_face_and_clipping_plane_follow_their_dragged_handles") {
    const auto dir = test::fresh_folder("viewer", "cut-handles");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const std::string setup = "view anterior\ncrop -60 -90 -40 60 60 50\nclip 0 0 0 0 0 -1\n";
    // (one frame in flight: the plane changes the layers, and the graph made again must wait
    // for the frame the window still shows)
    const auto first =
        view(dir, setup + "report " + d("r0.json") + "\nquit\n", "--no-panel --frames-in-flight 1");
    REQUIRE_MESSAGE(first.exit_code == 0, first.output);
    CHECK(first.output.find("validation") == std::string::npos);
    const Scene scene = load_scene(kScene);
    const auto report = [&](const char* name) {
      return nlohmann::json::parse(test::read_file(dir / name));
    };
    const Camera camera = reported_camera(dir / "r0.json");
    const auto pixel = [&](glm::vec3 p) { return project(camera, p, {kWidth, kHeight}).pixel; };
    // The bottom face's handle: its centre; the plane's: the centre of its cut through the
    // content (the content's box at z = 0). Each is dragged 12 px down the picture (towards -z).
    const glm::vec3 bottom(0.0f, -15.0f, -40.0f);
    const Bounds content = scene_bounds(scene);
    const glm::vec3 on_plane(0.5f * (content.lo.x + content.hi.x),
                             0.5f * (content.lo.y + content.hi.y), 0.0f);
    const auto drag = [&](glm::vec3 handle) {
      const glm::vec2 from = pixel(handle);
      return "drag left " + std::to_string(from.x) + " " + std::to_string(from.y) + " " +
             std::to_string(from.x) + " " + std::to_string(from.y + 12.0f) + "\n";
    };
    const auto r = view(dir,
                        setup + "screenshot " + d("before.png") + "\n" + drag(bottom) + "report " +
                            d("r1.json") + "\nscreenshot " + d("face.png") + "\n" + drag(on_plane) +
                            "report " + d("r2.json") + "\nscreenshot " + d("plane.png") +
                            "\nclip 0 0 0 1 0 0\nreport " + d("r3.json") + "\nclip off\nreport " +
                            d("r4.json") + "\nquit\n",
                        kManySteps);
    REQUIRE_MESSAGE(r.exit_code == 0, r.output);
    CHECK(r.output.find("validation") == std::string::npos);
    // The millimetres 12 px are at each handle, along its direction (+z for both drags).
    const auto mm = [&](glm::vec3 at) {
      return 12.0f / glm::distance(pixel(at), pixel(at + glm::vec3(0, 0, 1)));
    };
    const nlohmann::json r1 = report("r1.json"), r2 = report("r2.json");
    CHECK(r1.at("crop")[2].get<float>() == doctest::Approx(-40.0f - mm(bottom)).epsilon(0.1));
    CHECK(r1.at("crop")[5].get<float>() == 50.0f);  // (the other faces stay)
    CHECK(r1.at("clip")[0][3].get<float>() == 0.0f);
    // The plane (0, 0, -1, w) keeps z <= w: dragged down, it keeps less.
    CHECK(r2.at("clip")[0][3].get<float>() == doctest::Approx(-mm(on_plane)).epsilon(0.1));
    CHECK(r2.at("crop") == r1.at("crop"));
    // (a second plane is added to the first; "clip off" removes both)
    CHECK(report("r3.json").at("clip").size() == 2);
    CHECK(report("r3.json").at("clip")[0] == r2.at("clip")[0]);
    CHECK(report("r4.json").at("clip").empty());
    const Rgba8Image before = read_png(d("before.png")), face = read_png(d("face.png"));
    CHECK(changed_pixels(before, face) > 100);
    CHECK(changed_pixels(face, read_png(d("plane.png"))) > 100);
  }

  TEST_CASE("viewer_places_renames_moves_deletes_undoes_and_saves_labels") {
    const auto dir = test::fresh_folder("viewer", "own-labels");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto r = view(
        dir,
        "view anterior\nplace 80 40\nplace 66 70\nkey p\ndrag left 80 40 72 34\nkey p\nreport " +
            d("front.json") +
            "\nview left\nplace 80 60\nplace 60 50\nplace 100 70\n"
            "text 0 \"Thalamus R – Ödem \\\"rechts\\\"\"\nmove 4 90 45\n"
            "delete 5\nundo\nreport " +
            d("left.json") + "\nsave " + d("own.mrk.json") + " ras\nsave " + d("own.fcsv") +
            " lps\nquit\n",
        kManySteps);
    REQUIRE_MESSAGE(r.exit_code == 0, r.output);
    // (new labels take the lowest ids the scene's 11 leave free: 0, 4, 5, 6, 7)
    for (const char* id : {"(label 0)", "(label 4)", "(label 5)", "(label 6)", "(label 7)"})
      CHECK(r.output.find(id) != std::string::npos);
    const std::vector<Label> ras = load_label_file(d("own.mrk.json"));
    const std::vector<Label> lps = load_label_file(d("own.fcsv"));
    REQUIRE(ras.size() == 5);
    REQUIRE(lps.size() == 5);
    for (size_t i = 0; i < ras.size(); ++i) {
      CAPTURE(i);
      CHECK(ras[i].text == lps[i].text);
      CHECK(glm::distance(ras[i].anchor, lps[i].anchor) <= 0.01f);
    }
    CHECK(ras[0].text == "Thalamus R – Ödem \"rechts\"");
    // (each placed or moved anchor projects to the centre of its pixel in its view's camera)
    const Camera front = reported_camera(dir / "front.json");
    const Camera left = reported_camera(dir / "left.json");
    const struct {
      size_t index;
      const Camera* camera;
      glm::vec2 pixel;
    } placed[] = {{0, &front, {72, 34}},
                  {1, &left, {90, 45}},
                  {2, &left, {80, 60}},
                  {3, &left, {60, 50}},
                  {4, &left, {100, 70}}};
    for (const auto& p : placed) {
      CAPTURE(p.index);
      const ProjectedPoint at = project(*p.camera, ras[p.index].anchor, {kWidth, kHeight});
      CHECK(at.visible);
      CHECK(glm::distance(at.pixel, p.pixel + 0.5f) <= 0.05f);
    }
    const auto rendered = run_strata(
        "render " STRATA_SOURCE_DIR "/assets/cache/mricron/ch2.nii.gz --labels " +
        d("own.mrk.json") + " --size 384 --layout " + d("render.json") + " -o " + d("render.png"));
    REQUIRE_MESSAGE(rendered.exit_code == 0, rendered.output);
    const auto layout = nlohmann::json::parse(test::read_file(dir / "render.json"));
    for (size_t i = 0; i < ras.size(); ++i) {
      CAPTURE(ras[i].text);
      bool drawn = false;
      for (const auto& l : layout.at("labels"))
        drawn = drawn || (l.at("text") == ras[i].text && l.at("placed").get<bool>());
      CHECK(drawn);
    }
  }

  // The workflow of docs/viewer.md: open the scene, place a label, save; open the scene with the
  // saved file, place one more, save to the same file; three times. The file holds the labels
  // placed (1, 2, 3), never the scene's own, and the scene with it draws each label once. A file
  // that holds the scene's labels too (as saved before) adds them once, with a warning.
  TEST_CASE("saved_labels_read_back_once_over_three_open_edit_save_cycles") {
    const auto dir = test::fresh_folder("viewer", "save-cycles");
    const std::string saved = (dir / "mine.mrk.json").string();
    const char* pixels[] = {"80 60", "60 50", "100 70"};
    for (size_t cycle = 0; cycle < 3; ++cycle) {
      CAPTURE(cycle);
      const auto r = view(
          dir, std::string("view left\nplace ") + pixels[cycle] + "\nsave " + saved + "\nquit\n",
          "--no-panel" + (cycle > 0 ? " --labels " + saved : std::string()));
      REQUIRE_MESSAGE(r.exit_code == 0, r.output);
      CHECK(r.output.find("the scene's 11 stay in its file") != std::string::npos);
      CHECK(load_label_file(saved).size() == cycle + 1);
    }
    const auto labels_drawn = [&](const std::string& file) {
      const auto layout = dir / "layout.json";
      const auto r = run_strata("render " + kScene + " --labels " + file + " --size 96 --layout " +
                                layout.string() + " -o " + (dir / "render.png").string());
      INFO(r.output);
      CHECK(r.exit_code == 0);
      return std::pair{nlohmann::json::parse(test::read_file(layout)).at("labels").size(),
                       r.output};
    };
    CHECK(labels_drawn(saved).first == 14);
    // (the scene's 11 and the 3 placed in one file)
    std::vector<Label> both = load_scene(kScene).labels;
    for (const Label& l : load_label_file(saved)) both.push_back(l);
    const auto old = dir / "old.mrk.json";
    write_label_file(old, both, LabelAxes::ras);
    const auto [count, output] = labels_drawn(old.string());
    CHECK(count == 14);
    CHECK(output.find("strata: warning: " + old.string() +
                      ": 11 of its labels the scene has already (the same text and anchor): "
                      "added once") != std::string::npos);
  }

  // Labels placed in a scene whose largest id is 2147483647 take the lowest ids free (a file's
  // labels added with --labels too); a text that is not UTF-8 is refused when it is entered, and
  // a text with a NUL when it is saved into a .fcsv file (which cannot hold it).
  TEST_CASE("viewer_labels_take_free_ids_and_texts_a_file_cannot_hold_are_refused_with_why") {
    const auto dir = test::fresh_folder("viewer", "ids-text");
    const auto scene = test::write_file(
        dir / "scene.json",
        R"({"strata_scene": 1, "volumes": [{"name": "head", "file": ")" STRATA_SOURCE_DIR
        R"(/assets/cache/mricron/ch2.nii.gz"}], "labels": [
          {"id": 2147483647, "text": "Top", "anchor": [0, 17, 60]},
          {"id": 1, "text": "Middle", "anchor": [0, 17, 19]}]})");
    const std::vector<Label> nul = {
        Label{.id = 5, .text = std::string("a\0b", 3), .anchor = {0.0f, 17.0f, 30.0f}}};
    write_label_file(dir / "nul.mrk.json", nul);
    const auto run = [&](const std::string& script) {
      return run_strata("--validate view " + scene.string() + " --size 160x120 --no-panel " +
                        "--labels " + (dir / "nul.mrk.json").string() + " --script " +
                        test::write_file(dir / "script.txt", script).string());
    };
    const auto fcsv = dir / "own.fcsv";
    const auto placed =
        run("view anterior\nplace 80 60\nplace 70 50\nsave " + fcsv.string() + "\nquit\n");
    INFO(placed.output);
    CHECK(placed.exit_code == 1);
    CHECK(placed.output.find("(label 2)") != std::string::npos);
    CHECK(placed.output.find("(label 3)") != std::string::npos);
    CHECK(placed.output.find("-2147483648") == std::string::npos);
    CHECK(placed.output.find(fcsv.string() +
                             ": labels[0] (id 0): the text has a NUL character, which a .fcsv file "
                             "cannot hold (write .mrk.json)") != std::string::npos);
    CHECK(!std::filesystem::exists(fcsv));
    const auto latin1 =
        run("text 1 \"\xD6"
            "dem\"\nquit\n");
    INFO(latin1.output);
    CHECK(latin1.exit_code == 1);
    CHECK(latin1.output.find(":1: label 1: the text is not UTF-8") != std::string::npos);
  }

  // A place picks the picture as drawn, `strata pick` the scene's picture without labels
  // (docs/viewer.md): inside a ghosting lens (a scene label's, then the lens of the label just
  // placed there) a place goes through what the lens opens, behind the point `strata pick`
  // finds; with ghosting off, a place finds that point.
  TEST_CASE("viewer_place_picks_through_ghosting_lenses_and_without_them_where_pick_does") {
    const auto dir = test::fresh_folder("viewer", "place-lens");
    const auto r = view(dir, "place 80 60\nplace 80 60\nreport " + (dir / "r.json").string() +
                                 "\nset ghost 0\nplace 80 60\nsave " +
                                 (dir / "placed.mrk.json").string() + "\nquit\n");
    REQUIRE_MESSAGE(r.exit_code == 0, r.output);
    const std::vector<Label> placed = load_label_file(dir / "placed.mrk.json");
    REQUIRE(placed.size() == 3);
    const auto pick = run_strata("pick " + kScene + " --size 160x120 --at 80,60");
    REQUIRE_MESSAGE(pick.exit_code == 0, pick.output);
    glm::vec3 picked{0.0f};
    REQUIRE(std::sscanf(pick.output.substr(pick.output.find("80,60: LPS ")).c_str(),
                        "80,60: LPS %f %f %f", &picked.x, &picked.y, &picked.z) == 3);
    const Camera camera = reported_camera(dir / "r.json");
    const auto at = [&](glm::vec3 p) { return project(camera, p, {kWidth, kHeight}); };
    for (const Label& l : placed)
      CHECK(glm::distance(at(l.anchor).pixel, glm::vec2(80.5f, 60.5f)) <= 0.05f);
    CHECK(at(placed[0].anchor).eye_depth > at(picked).eye_depth + 0.5f);
    CHECK(at(placed[1].anchor).eye_depth > at(placed[0].anchor).eye_depth + 0.5f);
    CHECK(glm::distance(placed[2].anchor, picked) <= 0.02f);
  }

  TEST_CASE("viewer_script_rotates_zooms_pans_jumps_reweights_and_hides") {
    const auto dir = test::fresh_folder("viewer", "script");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto r = view(
        dir,
        "layout " + d("base.json") + "\nscreenshot " + d("base.png") +
            "\ndrag left 80 60 110 60\nlayout " + d("rotated.json") + "\nscreenshot " +
            d("rotated.png") + "\nscroll -2\nlayout " + d("zoomed.json") +
            "\ndrag middle 80 60 92 52\nlayout " + d("panned.json") +
            "\nkey 2\nreport camera\nlayout " + d("left.json") + "\nscreenshot " + d("left.png") +
            "\nhide 3\nlayout " + d("hidden.json") + "\nscreenshot " + d("hidden.png") +
            "\nset forces.keep_apart off\nhide 60\nhide 52\nhide 81\nhide 29\nhide 31\nhide 37"
            "\nlayout " +
            d("few.json") +
            "\nset weights.anchor_constraint 0\nset weights.distance_to_anchor 1\n"
            "set weights.leader_crossing 0\nlayout " +
            d("weighted.json") + "\nquit\n",
        // (the layouts this test expects are those of the placement in each frame, in the
        // scene's insertion order: the optimisation on idle's orders would blur what the
        // weights change)
        "--no-optimize --no-panel --frame-budget 0");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("validation") == std::string::npos);
    // `report camera` prints the camera of the scene's second position.
    CHECK(r.output.find("view: camera eye ") != std::string::npos);
    CHECK(r.output.find(", fov ") != std::string::npos);

    // Left drag: the scene turns (anchors move, the picture changes).
    const auto base = read_layout(d("base.json")), rotated = read_layout(d("rotated.json"));
    float moved = 0.0f;
    for (size_t i = 0; i < base.size(); ++i)
      moved += glm::length(rotated[i].anchor - base[i].anchor);
    CHECK(moved / float(base.size()) > 5.0f);
    CHECK(changed_pixels(read_png(d("base.png")), read_png(d("rotated.png"))) > 2000);

    // The wheel toward the user zooms in: the anchors spread out.
    const auto zoomed = read_layout(d("zoomed.json"));
    CHECK(spread(zoomed) > 1.3f * spread(rotated));

    // Middle drag: the content follows the mouse (anchors near the target's depth exactly).
    const auto panned = read_layout(d("panned.json"));
    for (size_t i = 0; i < zoomed.size(); ++i) {
      if (!inside(zoomed[i].anchor)) continue;
      const glm::vec2 delta = panned[i].anchor - zoomed[i].anchor;
      CHECK(delta.x == doctest::Approx(12.0f).epsilon(0.25));
      CHECK(delta.y == doctest::Approx(-8.0f).epsilon(0.25));
    }

    // Key 2: the scene's second position ("left"), where `strata render --camera left` has the
    // same anchors.
    const auto still = d("render-left.json");
    const auto rendered =
        run_strata("render " + kScene + " --camera left --size " + std::to_string(kWidth) + "x" +
                   std::to_string(kHeight) + " -o " + d("render-left.png") + " --layout " + still);
    REQUIRE(rendered.exit_code == 0);
    const auto left = read_layout(d("left.json")), expected = read_layout(still);
    for (size_t i = 0; i < left.size(); ++i) {
      CHECK(left[i].anchor.x == doctest::Approx(expected[i].anchor.x).epsilon(1e-3));
      CHECK(left[i].anchor.y == doctest::Approx(expected[i].anchor.y).epsilon(1e-3));
    }

    // Hiding label 3: gone from the layout, and its box's pixels change where the layout had it.
    const auto find = [](const std::vector<LabelBox>& ls, int id) {
      for (const auto& l : ls) {
        if (l.id == id) return l;
      }
      FAIL("no label " << id);
      return LabelBox{};
    };
    const auto hidden = read_layout(d("hidden.json"));
    const LabelBox before = find(left, 3);
    REQUIRE(before.shown);
    CHECK_FALSE(find(hidden, 3).shown);
    const Rgba8Image was = read_png(d("left.png")), now = read_png(d("hidden.png"));
    const size_t in_box = changed_pixels(was, now, before.box);
    CHECK(double(in_box) > 0.35 * double(before.box.z * before.box.w));

    // Without the anchor constraint's and the tidy-up's crossing weights and with a heavier leader
    // length, the four labels left move toward their anchors. (Labels not kept apart: in the
    // 160 x 120 window the four boxes do not all fit side by side.)
    const auto few = read_layout(d("few.json")), weighted = read_layout(d("weighted.json"));
    CHECK(std::count_if(few.begin(), few.end(), [](const LabelBox& l) { return l.shown; }) == 4);
    CHECK(mean_leader(weighted) < 0.8f * mean_leader(few));
  }

  TEST_CASE("viewer_panel_screenshot_key_recording_and_idle") {
    const auto dir = test::fresh_folder("viewer", "panel");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto r = view(dir,
                        "screenshot " + d("picture.png") + "\ncapture " + d("window.png") +
                            "\nkey f12\nreport " + d("still-1.json") + "\nsleep 1.5\nreport " +
                            d("still-2.json") + "\nrecord start " + d("clip.mp4") +
                            "\ndrag left 80 60 100 60\nframes 4\nreport " + d("recorded.json") +
                            "\nrecord stop\nquit\n",
                        "");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);

    // The panel is in the window's picture, not in the screenshot.
    const Rgba8Image picture = read_png(d("picture.png")), window = read_png(d("window.png"));
    CHECK(changed_pixels(picture, window, glm::vec4(0, 0, 80, 40)) > 1000);

    // F12 wrote a screenshot into --screenshot-dir.
    size_t pngs = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      if (e.path().filename().string().rfind("head-", 0) == 0) ++pngs;
    }
    CHECK(pngs == 1);

    // Still camera, settled labels: no frames while the script slept.
    const auto frames = [&](const char* name) {
      return nlohmann::json::parse(test::read_file(d(name))).at("frames").get<int>();
    };
    CHECK(nlohmann::json::parse(test::read_file(d("still-1.json"))).at("settled") == true);
    CHECK(frames("still-2.json") == frames("still-1.json"));

    // Every frame drawn while recording is in the video (the optimisation on idle waits for the
    // recording's end).
    const int recorded = frames("recorded.json") - frames("still-2.json");
    CHECK(recorded >= 4);
#if STRATA_VIDEO
    CHECK(test::probe_video(d("clip.mp4"), "nb_read_frames") == std::to_string(recorded));
#endif
  }

  // Labels are placed off the panel: with it open, no drawn box touches its rectangle (and some
  // labels are drawn beside it); without it, labels take that room.
  TEST_CASE("viewer_places_no_label_under_its_panel") {
    const auto dir = test::fresh_folder("viewer", "panel-room");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto script = test::write_file(
        dir / "script.txt", "report " + d("open.json") + "\nlayout " + d("open-layout.json") +
                                "\nscreenshot " + d("open.png") + "\nquit\n");
    const auto r =
        run_strata("--validate view " + kScene + " --size 640x240 --script " + script.string());
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const auto panel = nlohmann::json::parse(test::read_file(d("open.json"))).at("panel");
    REQUIRE(panel.size() == 4);
    const glm::vec4 rect(panel[0].get<float>(), panel[1].get<float>(), panel[2].get<float>(),
                         panel[3].get<float>());
    CHECK(rect.z - rect.x > 100.0f);
    // Drawn boxes (opacity above 0) that touch the panel's rectangle, and drawn boxes.
    const auto count = [&](const char* layout) {
      int touching = 0, drawn = 0;
      const auto json = nlohmann::json::parse(test::read_file(d(layout)));
      for (const auto& l : json.at("labels")) {
        if (l.value("opacity", 1.0) <= 0.0 || !l.contains("box") || l.at("box").is_null()) continue;
        const auto& b = l.at("box");
        const float x = b[0].get<float>(), y = b[1].get<float>();
        const float w = b[2].get<float>(), h = b[3].get<float>();
        ++drawn;
        if (x < rect.z && rect.x < x + w && y < rect.w && rect.y < y + h) ++touching;
      }
      return std::pair{touching, drawn};
    };
    const auto [open_touching, open_drawn] = count("open-layout.json");
    CHECK(open_touching == 0);
    CHECK(open_drawn >= 3);
    // Without the panel, labels take that room.
    const auto bare = run_strata(
        "--validate view " + kScene + " --size 640x240 --no-panel --script " +
        test::write_file(dir / "bare.txt", "layout " + d("bare-layout.json") + "\nquit\n")
            .string());
    INFO(bare.output);
    REQUIRE(bare.exit_code == 0);
    const auto [bare_touching, bare_drawn] = count("bare-layout.json");
    CHECK(bare_touching >= 1);
    CHECK(bare_drawn >= open_drawn);
  }

  // A title and a legend with the panel open: no drawn label touches any of them, the layout
  // records the title's and legend's boxes, and `set legend off` gives the legend's room back.
  TEST_CASE("viewer_places_no_label_under_its_panel_title_or_legend") {
    const auto dir = test::fresh_folder("viewer", "annotations");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto script = test::write_file(
        dir / "script.txt", "report " + d("report.json") + "\nlayout " + d("layout.json") +
                                "\nscreenshot " + d("shot.png") + "\nset legend off\nlayout " +
                                d("no-legend.json") + "\nquit\n");
    const auto r = run_strata("--validate view " + kScene + " --size 640x360 --title Head --legend " +
                              "--script " + script.string());
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const auto panel = nlohmann::json::parse(test::read_file(d("report.json"))).at("panel");
    REQUIRE(panel.size() == 4);
    // Drawn boxes (opacity above 0) touching the panel, the title or the legend.
    const auto layout = nlohmann::json::parse(test::read_file(d("layout.json")));
    std::vector<glm::vec4> kept{{panel[0].get<float>(), panel[1].get<float>(),
                                 panel[2].get<float>(), panel[3].get<float>()}};
    REQUIRE(layout.at("annotations").size() == 2);
    for (const auto& a : layout.at("annotations")) {
      const auto& b = a.at("box");
      const float x = b[0].get<float>(), y = b[1].get<float>();
      kept.push_back({x, y, x + b[2].get<float>(), y + b[3].get<float>()});
    }
    int drawn = 0, touching = 0;
    for (const auto& l : layout.at("labels")) {
      if (l.value("opacity", 1.0) <= 0.0) continue;
      ++drawn;
      const auto& b = l.at("box");
      const float x = b[0].get<float>(), y = b[1].get<float>();
      const float w = b[2].get<float>(), h = b[3].get<float>();
      for (const glm::vec4& k : kept) touching += x < k.z && k.x < x + w && y < k.w && k.y < y + h;
    }
    CHECK(touching == 0);
    CHECK(drawn >= 2);
    const auto no_legend = nlohmann::json::parse(test::read_file(d("no-legend.json")));
    REQUIRE(no_legend.at("annotations").size() == 1);
    CHECK(no_legend.at("annotations")[0].at("name") == "title");
  }

  // The placement beside the frames (on lavapipe's one queue: its own submissions after the
  // frames that feed it): the frames draw the newest finished placement's layout, which follows
  // the camera and settles as clean as the placement in each frame does.
  TEST_CASE("viewer_with_the_placement_beside_the_frames_settles_on_a_clean_layout") {
    const auto dir = test::fresh_folder("viewer", "beside");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto script = test::write_file(
        dir / "script.txt", "layout " + d("rest.json") + "\ndrag left 40 60 120 60\nlayout " +
                                d("turned.json") + "\nquit\n");
    const auto r = run_strata("--validate view " + kScene + " --size " + std::to_string(kWidth) +
                              "x" + std::to_string(kHeight) +
                              " --no-panel --placement beside --script " + script.string());
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("view: placement beside the frames: ") != std::string::npos);
    for (const char* layout : {"rest.json", "turned.json"}) {
      CAPTURE(layout);
      const std::vector<LabelBox> labels = read_layout(d(layout));
      int shown = 0, overlapping = 0, outside = 0;
      for (size_t i = 0; i < labels.size(); ++i) {
        if (!labels[i].shown) continue;
        ++shown;
        const glm::vec4 a = labels[i].box;
        if (a.x < -0.5f || a.y < -0.5f || a.x + a.z > kWidth + 0.5f || a.y + a.w > kHeight + 0.5f) {
          ++outside;
        }
        for (size_t j = i + 1; j < labels.size(); ++j) {
          const glm::vec4 b = labels[j].box;
          if (labels[j].shown && a.x < b.x + b.z && b.x < a.x + a.z && a.y < b.y + b.w &&
              b.y < a.y + a.w) {
            ++overlapping;
          }
        }
      }
      CHECK(shown >= 3);
      CHECK(overlapping == 0);
      CHECK(outside == 0);
    }
    // The drag turned the head: the labels followed their anchors.
    CHECK(read_layout(d("rest.json"))[0].anchor != read_layout(d("turned.json"))[0].anchor);
  }

  // Interactive rendering: while the camera moves (a named view's animation) rays are cast for
  // fewer pixels to hold the frame budget; at rest the full picture again.
  TEST_CASE("viewer_casts_fewer_rays_while_the_camera_moves_and_refines_at_rest") {
    const auto dir = test::fresh_folder("viewer", "interactive");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const std::string size = " --size " + std::to_string(kWidth) + "x" + std::to_string(kHeight);
    const auto run = [&](const char* budget, const char* name) {
      const auto script = test::write_file(dir / (std::string(name) + ".txt"),
                                           "view left\ncapture " + d(name) + ".png\nquit\n");
      // (the head's volume alone: no labels to tell the pictures apart)
      return run_strata("--validate view " STRATA_SOURCE_DIR "/assets/cache/mricron/ch2.nii.gz" +
                        size + " --no-panel --frame-budget " + budget + " --script " +
                        script.string());
    };
    const auto fast = run("1", "fast");
    INFO(fast.output);
    REQUIRE(fast.exit_code == 0);
    // (a budget of 1 ms: the largest divisor while moving)
    CHECK(fast.output.find("8 x 8 pixels to a ray at most") != std::string::npos);
    CHECK(fast.output.find("full quality ") != std::string::npos);
    const auto full = run("0", "full");
    INFO(full.output);
    REQUIRE(full.exit_code == 0);
    CHECK(full.output.find("1 x 1 pixels to a ray at most") != std::string::npos);
    // At rest, the same picture as without interactive rendering.
    CHECK(changed_pixels(read_png(d("fast.png")), read_png(d("full.png"))) == 0);
  }

  // The optimisation on idle (the default) with the placement beside the frames (lavapipe's
  // default with interactive rendering): its trials are placements of their own, which the frames
  // never adopt. A script's first command runs once all are back, well within the settle limit,
  // and the viewer at rest then draws nothing.
  TEST_CASE("viewer_with_its_default_optimisation_settles_well_within_the_limit_and_then_sleeps") {
    const auto dir = test::fresh_folder("viewer", "optimize-beside");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto start = std::chrono::steady_clock::now();
    const auto r = view(dir,
                        "screenshot " + d("x.png") + "\nreport " + d("rest.json") +
                            "\nsleep 1\nreport " + d("slept.json") + "\nquit\n",
                        "--no-panel --settle-limit 60");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    // (well within the limit: about 5 s on lavapipe)
    CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(30));
    CHECK(r.output.find("view: placement beside the frames: ") != std::string::npos);
    const auto report = [&](const char* name) {
      return nlohmann::json::parse(test::read_file(d(name)));
    };
    CHECK(report("rest.json").at("trials") == 8);
    CHECK(report("rest.json").at("settled") == true);
    CHECK(report("rest.json").at("busy") == false);
    CHECK(report("slept.json").at("frames") == report("rest.json").at("frames"));
  }

  TEST_CASE("viewer_tries_insertion_orders_when_the_camera_rests") {
    // Optimisation on idle: once the view has rested, trial frames try random orders (labels
    // stay where they are meanwhile); a camera move starts it again; then nothing is drawn.
    // (Trials are frames that place: the placement in the frame, no interactive rendering.)
    const auto dir = test::fresh_folder("viewer", "optimize");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto r = view(dir,
                        "report " + d("opened.json") + "\ndrag left 80 60 90 60\nreport " +
                            d("moved.json") + "\nsleep 1.5\nreport " + d("still.json") + "\nquit\n",
                        "--no-panel --frame-budget 0");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const auto field = [&](const char* name, const char* key) {
      return nlohmann::json::parse(test::read_file(d(name))).at(key).get<int>();
    };
    // (each command waits for the view to settle: the trials have all come back)
    CHECK(field("opened.json", "trials") == 8);
    CHECK(field("moved.json", "trials") == 16);
    CHECK(field("moved.json", "frames") >= field("opened.json", "frames") + 8);
    CHECK(field("still.json", "frames") == field("moved.json", "frames"));
  }

  TEST_CASE("viewer_answers_real_x_events") {
    // The wiring from X to the viewer: xdotool's key and mouse events (XTEST), as a user's.
    const auto dir = test::fresh_folder("viewer", "xdotool");
    const std::string log = (dir / "log.txt").string();
    const std::string command = std::string(STRATA_BINARY) + " --validate view " + kScene +
                                " --size 160x120 --no-panel --screenshot-dir " + dir.string() +
                                " > " + log + " 2>&1 &";
    REQUIRE(std::system(command.c_str()) == 0);
    const auto sh = [](const std::string& c) { return std::system(c.c_str()); };
    REQUIRE(sh("xdotool search --sync --name 'strata - head.json' > /dev/null") == 0);
    const auto wait_for = [&](const std::function<bool()>& done) {
      for (int i = 0; i < 1200 && !done(); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      return done();
    };
    const auto screenshots = [&] {
      size_t n = 0;
      for (const auto& e : std::filesystem::directory_iterator(dir)) {
        if (e.path().extension() == ".png") ++n;
      }
      return n;
    };
    const std::string window = "$(xdotool search --name 'strata - head.json' | head -1)";
    // (settled first: the first frames take a while on lavapipe)
    std::this_thread::sleep_for(std::chrono::seconds(3));
    CHECK(sh("xdotool key --window " + window + " F12") == 0);
    REQUIRE(wait_for([&] { return screenshots() == 1; }));
    // A left drag across the window turns the scene.
    CHECK(sh("xdotool mousemove --window " + window + " 60 60 mousedown 1 mousemove --window " +
             window + " 80 60 mousemove --window " + window + " 110 60 mouseup 1") == 0);
    std::this_thread::sleep_for(std::chrono::seconds(4));
    CHECK(sh("xdotool key --window " + window + " F12") == 0);
    REQUIRE(wait_for([&] { return screenshots() == 2; }));
    CHECK(sh("xdotool key --window " + window + " q") == 0);
    REQUIRE(wait_for([&] { return test::read_file(log).find("frames at") != std::string::npos; }));
    const std::string out = test::read_file(log);
    INFO(out);
    CHECK(out.find("validation") == std::string::npos);
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      if (e.path().extension() == ".png") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    REQUIRE(files.size() == 2);
    CHECK(changed_pixels(read_png(files[0].string()), read_png(files[1].string())) > 1000);
  }

  // A preset chosen in the viewer is copied in the next frame (no wait): the picture equals that
  // of a viewer opened with it, byte for byte. mr-head shows the skin that mr-brain leaves
  // transparent, so an empty-space grid left from mr-brain would skip it.
  TEST_CASE("a_preset_switched_in_the_viewer_draws_what_a_viewer_opened_with_it_does") {
    const auto dir = test::fresh_folder("viewer", "preset-in-frame");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto run = [&](const char* preset, const std::string& script) {
      const auto path = test::write_file(dir / "script.txt", script);
      const auto r = run_strata("--validate view " STRATA_SOURCE_DIR
                                "/assets/cache/mricron/ch2.nii.gz --size 96 "
                                "--no-panel --preset " +
                                std::string(preset) + " --script " + path.string());
      INFO(r.output);
      CHECK(r.exit_code == 0);
      CHECK(r.output.find("validation") == std::string::npos);
    };
    run("mr-brain", "screenshot " + d("brain.png") + "\npreset mr-head\nscreenshot " +
                        d("switched.png") + "\nquit\n");
    run("mr-head", "screenshot " + d("head.png") + "\nquit\n");
    const Rgba8Image head = read_png(d("head.png"));
    CHECK(changed_pixels(read_png(d("brain.png")), head) > 500);
    CHECK(changed_pixels(read_png(d("switched.png")), head) == 0);
  }

  // A volume opened directly: the fitted views and the presets are the viewer's too.
  TEST_CASE("viewer_opens_a_volume_with_its_anatomical_views_and_switches_presets") {
    const auto dir = test::fresh_folder("viewer", "volume");
    const auto d = [&](const char* name) { return (dir / name).string(); };
    const auto script = test::write_file(
        dir / "script.txt", "screenshot " + d("head.png") + "\npreset mr-brain\nscreenshot " +
                                d("brain.png") + "\nview superior\nscreenshot " + d("top.png") +
                                "\npreset ct-bone\nscreenshot " + d("bone.png") + "\nquit\n");
    const auto r = run_strata("--validate view " STRATA_SOURCE_DIR
                              "/assets/cache/mricron/ch2.nii.gz --size 96 "
                              "--no-panel --script " +
                              script.string());
    INFO(r.output);
    CHECK(r.output.find("validation") == std::string::npos);
    CHECK(r.output.find("preset mr-head") != std::string::npos);  // chosen and said
    CHECK(r.exit_code == 0);
    const Rgba8Image head = read_png(d("head.png")), brain = read_png(d("brain.png"));
    const Rgba8Image bone = read_png(d("bone.png")), top = read_png(d("top.png"));
    CHECK(changed_pixels(head, brain) > 500);
    CHECK(changed_pixels(brain, top) > 500);  // from above
    // ct-bone on an MR: hardly a value reaches bone's Hounsfield units; the head all but goes.
    CHECK(changed_pixels(top, bone) > 2000);
  }
}

}  // namespace strata
