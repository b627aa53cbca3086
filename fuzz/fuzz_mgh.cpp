// FreeSurfer MGH (mgh.cpp) on fuzzed bytes saved as input.mgz (raw or gzip, as the bytes start).
// Where the input loads, frame 1 is asked for as well: a 4-D image then skips a frame, a 3-D one
// refuses.
#include "engine/scene/io/volume_loader.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.mgz");
  std::vector<std::string> warnings;
  strata::fuzz::expect_only_errors([&] {
    strata::load_mgh(path, {}, warnings);
    strata::load_mgh(path, {.frame = 1}, warnings);
  });
  return 0;
}
