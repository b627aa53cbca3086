// The documentation a newcomer follows: every example file in docs/scene-format.md loads, the
// example camera named "front" looks at the face, and no page points outside the repository.
#include <doctest/doctest.h>

#include <filesystem>
#include <optional>
#include <sstream>

#include <glm/glm.hpp>

#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace {

const fs::path source = STRATA_SOURCE_DIR;

using strata::test::code_blocks;
using strata::test::CodeBlock;

// The example scene's paths are as seen from assets/scenes/: a copy of that layout with the
// repository's data linked in, and a small mesh for the example's skull.ply.
fs::path example_folder() {
  const fs::path root = strata::test::fresh_folder("docs_tests", "examples");
  fs::create_directories(root / "scenes");
  fs::create_directories(root / "models");
  fs::create_directory_symlink(source / "assets/cache", root / "cache");
  fs::create_directory_symlink(source / "assets/transfer_functions", root / "transfer_functions");
  fs::create_directory_symlink(source / "assets/scenes/pictures", root / "scenes/pictures");
  strata::test::write_file(root / "models/skull.ply",
                           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n10 0 0\n0 10 0\n3 0 1 2\n");
  return root;
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("every_example_in_the_scene_format_page_loads_and_front_looks_at_the_face") {
    const std::string page = strata::test::read_file(source / "docs/scene-format.md");
    const fs::path root = example_folder();
    size_t scenes = 0, transfer_functions = 0, label_files = 0;
    std::vector<glm::vec3> first_anchors;  // the label examples' first point, in strata's LPS
    const auto labels_of = [&](const fs::path& file) {
      const std::vector<strata::Label> labels = strata::load_label_file(file);
      REQUIRE(!labels.empty());
      first_anchors.push_back(labels.front().anchor);
      ++label_files;
    };
    for (const CodeBlock& block : code_blocks(page)) {
      INFO("docs/scene-format.md line " << block.line);
      const fs::path stem = root / "scenes" / ("example-" + std::to_string(block.line));
      if (block.text.find("\"strata_scene\"") != std::string::npos) {
        const fs::path file = strata::test::write_file(stem.string() + ".json", block.text);
        const strata::Scene scene = strata::load_scene(file);
        ++scenes;
        for (const strata::CameraPose& pose : scene.camera_positions) {
          if (pose.name != "front") continue;
          // LPS: the face is towards -y. The eye of "front" is there, looking at +y.
          const glm::mat4 eye_to_world = glm::inverse(pose.view);
          const glm::vec3 looking = -glm::vec3(eye_to_world[2]);
          CHECK(looking.y > 0.95f);
        }
      } else if (block.text.find("\"strata_transfer_function\"") != std::string::npos) {
        const fs::path file = strata::test::write_file(stem.string() + ".json", block.text);
        CHECK(!strata::load_transfer_function(file).stops.empty());
        ++transfer_functions;
      } else if (block.text.find("\"controlPoints\"") != std::string::npos) {
        labels_of(strata::test::write_file(stem.string() + ".mrk.json", block.text));
      } else if (block.text.starts_with("# Markups fiducial file")) {
        labels_of(strata::test::write_file(stem.string() + ".fcsv", block.text));
      } else if (block.language == "csv") {
        labels_of(strata::test::write_file(stem.string() + ".csv", block.text));
      }
    }
    CHECK(scenes >= 1);
    CHECK(transfer_functions >= 1);
    CHECK(label_files >= 3);
    // The RAS and LPS examples describe the same finding.
    for (const glm::vec3& anchor : first_anchors) CHECK(anchor == first_anchors.front());
  }

  TEST_CASE("the_docs_name_no_path_outside_the_repository_and_say_what_a_newcomer_needs") {
    std::vector<fs::path> pages = {source / "README.md"};
    for (const auto& entry : fs::directory_iterator(source / "docs")) {
      if (entry.path().extension() == ".md") pages.push_back(entry.path());
    }
    for (const fs::path& page : pages) {
      INFO(page.string());
      const std::string text = strata::test::read_file(page);
      CHECK(text.find("../shared") == std::string::npos);
    }
    const std::string readme = strata::test::read_file(source / "README.md");
    CHECK(readme.find("build/app/strata") < 600);  // where the program is, at the top
    CHECK(readme.find("cmake --install") != std::string::npos);
    const std::string metrics = strata::test::read_file(source / "docs/layout-metrics.md");
    CHECK(metrics.find("`cost` is what the placement paid") != std::string::npos);
    // The demo builds the program alone, not the tests.
    CHECK(strata::test::read_file(source / "scripts/demo").find("scripts/build.sh strata") !=
          std::string::npos);
  }
}
