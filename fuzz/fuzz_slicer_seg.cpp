// 3D Slicer's .seg.nrrd (slicer_segmentation.cpp) on fuzzed bytes saved as input.seg.nrrd: the
// SegmentN_ fields, the 3-D and 4-D (layers first) layouts, attached data or a data file the
// header names in the sandbox.
#include "engine/scene/segmentation.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.seg.nrrd");
  std::vector<std::string> warnings;
  strata::fuzz::expect_only_errors([&] { strata::load_slicer_segmentation(path, {}, warnings); });
  return 0;
}
