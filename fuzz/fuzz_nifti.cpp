// NIfTI-1 and NIfTI-2, raw or gzip (nifti.cpp), on fuzzed bytes saved as input.nii. Where the
// input loads, frame 1 is asked for as well: a 4-D image then skips a frame, a 3-D one refuses.
#include "engine/scene/io/volume_loader.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.nii");
  std::vector<std::string> warnings;
  strata::fuzz::expect_only_errors([&] {
    strata::load_nifti(path, {}, warnings);
    strata::load_nifti(path, {.frame = 1}, warnings);
  });
  return 0;
}
