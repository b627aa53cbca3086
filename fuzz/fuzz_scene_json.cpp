// strata scene JSON (scene_loader.cpp) through load_scene (parse, load what it references,
// complete_scene). The sandbox holds small files a scene may name (write_scene_files), so inputs
// reach the readers behind them.
#include "engine/scene/io/scene_loader.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  strata::fuzz::write_scene_files();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "scene.json");
  strata::fuzz::expect_only_errors([&] { strata::load_scene(path); });
  return 0;
}
