// The DICOM SEG reader (dicom_seg.cpp): is_dicom_seg's walk over the meta header in this process,
// then load_dicom_seg, whose GDCM parse and frame walk run in a child. An Error is what bad input
// must give. A child ended by a signal is GDCM's fault caught by the isolation (GDCM is not
// instrumented; its assertions abort); a child that exited with a status carries a sanitizer's
// report from strata's own frame walk, so that is a finding.
#include <string_view>

#include "engine/scene/segmentation.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.dcm");
  strata::fuzz::expect_only_errors([&] {
    strata::is_dicom_seg(path);
    // A header that lies about the grid or the overlaps is refused before its layers are made.
    strata::VolumeReadOptions options;
    options.limits.memory_bytes = uint64_t{256} << 20;
    options.parser = {.seconds = 5.0, .memory_bytes = uint64_t{512} << 20};
    std::vector<std::string> warnings;
    try {
      strata::load_dicom_seg(path, options, warnings);
    } catch (const strata::Error& e) {
      if (std::string_view(e.what()).find(" failed (exit status") != std::string_view::npos) {
        std::fprintf(stderr, "fuzz: the child's frame walk failed: %s\n", e.what());
        std::abort();
      }
    }
  });
  return 0;
}
