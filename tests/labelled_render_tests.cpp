// strata's main job end to end on the bundled head demo: every label in view is placed on
// screen, readable, and no two label boxes overlap.
#include <doctest/doctest.h>

#include <cstdlib>

#include "engine/png.h"
#include "engine/scene_loader.h"
#include "gpu_fixture.h"
#include "labeling/labelled_render.h"

namespace strata {

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "head_demo_labels_are_all_on_screen_and_never_overlap") {
    const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
    const graph::Extent size{256, 256};
    for (const char* camera : {"front", "oblique"}) {
      CAPTURE(camera);
      const LabelledFrame frame = render_labelled(ctx, scene, camera_for(scene, camera), size, {});
      REQUIRE(frame.labels.size() == scene.labels.size());
      for (const LabelLayout& l : frame.labels) {
        CAPTURE(l.text);
        CHECK(l.shown);
        CHECK(l.box_origin.x >= 0.0f);
        CHECK(l.box_origin.y >= 0.0f);
        CHECK(l.box_origin.x + l.box_size.x <= float(size.width));
        CHECK(l.box_origin.y + l.box_size.y <= float(size.height));
        CHECK(l.box_size.y >= 12.0f);  // room for the 14-pixel font's lowercase and padding
      }
      for (size_t i = 0; i < frame.labels.size(); ++i) {
        for (size_t j = i + 1; j < frame.labels.size(); ++j) {
          const LabelLayout& a = frame.labels[i];
          const LabelLayout& b = frame.labels[j];
          const bool apart = a.box_origin.x + a.box_size.x <= b.box_origin.x ||
                             b.box_origin.x + b.box_size.x <= a.box_origin.x ||
                             a.box_origin.y + a.box_size.y <= b.box_origin.y ||
                             b.box_origin.y + b.box_size.y <= a.box_origin.y;
          CHECK_MESSAGE(apart, a.text << " overlaps " << b.text);
        }
      }
      if (std::getenv("STRATA_KEEP_IMAGES")) {
        write_png(test::output_dir() + "/labelled-" + camera + ".png", size.width, size.height,
                  frame.image);
      }
    }
  }
}

}  // namespace strata
