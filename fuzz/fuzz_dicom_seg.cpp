// The DICOM SEG reader (dicom_seg.cpp): is_dicom_seg's walk over the meta header in this process,
// then load_dicom_seg, whose GDCM parse and frame walk run in a child. An Error is what bad input
// must give; a child that crashed or failed (a sanitizer's report ends it with a status) is a
// finding, since the frame walk there is strata's code.
#include <string_view>

#include "engine/scene/segmentation.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.dcm");
  strata::fuzz::expect_only_errors([&] {
    strata::is_dicom_seg(path);
    // Small limits: a header that lies about the grid is refused before the layers are made.
    strata::VolumeReadOptions options;
    options.limits.memory_bytes = uint64_t{64} << 20;
    options.parser = {.seconds = 20.0, .memory_bytes = uint64_t{256} << 20};
    std::vector<std::string> warnings;
    try {
      strata::load_dicom_seg(path, options, warnings);
    } catch (const strata::Error& e) {
      const std::string_view message = e.what();
      if (message.find(" crashed (") != std::string_view::npos ||
          message.find(" failed (exit status") != std::string_view::npos) {
        std::fprintf(stderr, "fuzz: the child ended abnormally: %s\n", e.what());
        std::abort();
      }
    }
  });
  return 0;
}
